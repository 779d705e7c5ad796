// Scene files: every key lands in its field, absent keys keep their defaults, and each kind of
// mistake is reported as "file:line: key: what", so that a person editing one by hand can fix it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "test_support.h"
#include "vrdeform/scene/scene_builder.h"
#include "vrdeform/scene/scene_file.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;
using testing::errorOf;

const fs::path kMeshes = VRDEFORM_SHARED_DIR "/data/meshes";

std::string meshPath(const std::string& name) { return fs::absolute(kMeshes / name).lexically_normal().string(); }

SceneSpec parse(std::string_view text) { return parseScene(text, "scene.toml", kMeshes); }
std::string errorIn(std::string_view text) {
  return errorOf([&] { parse(text); });
}

void writeText(const fs::path& path, std::string_view text) { std::ofstream(path, std::ios::binary) << text; }

// Every key of the schema, none at its default.
constexpr const char* kFullScene = R"(format = 1
name = "liver-demo"
description = "A liver poked and a flag pinched"
settle = 0.5
seconds = 3
wind = [20, 0, 1.5]

[solver]
rate = 120
substeps = 4
iterations = 8
gravity = [0, -9.8, 0.5]
linear_damping = 0.2
simd = false
threads = 2
fuse_strain_volume = false
measure_residuals = false
tolerance = 1e-3

[[body]]
name = "liver"
kind = "soft"
mesh = "liver_coarse.obj"
render_mesh = "orig/../liver.obj"
scale = 0.01
rotation = [90, 0, -45]
position = [0.1, 0.2, -0.3]
placement = "as_is"
mesher = "tetgen"
tets = 1500
constraints = ["edges", "shape_matching"]
force = [0, -1, 0]

[body.material]
youngs = 5000
poisson = 0.45
density = 1060
rayleigh_damping = 0.01
compliance = 0.2
damping = 0.04
particle_radius = 0.002

[body.material.volume]
compliance = 0.1

[body.material.strain_stretch]
damping = 0.05

[body.material.strain_shear]
compliance = 0.15
damping = 0.02

[body.material.shape_matching]
compliance = 0.5

[[body]]
name = "flag"
kind = "cloth"
mesh = "flag_plane.obj"
placement = "ground"
pin = ["-x", "+y"]
pin_tolerance = 0.01

[body.material]
compliance = 1e-4
damping = 0
particle_mass = 0.05

[body.material.distance]
compliance = 2e-4
damping = 0.01

[body.material.bending]
damping = 0.06

[[body]]
mesh = "bunny_coarse.obj"
mesher = "builtin"
max_volume = 1e-6

[[collider]]
type = "plane"
normal = [0, 0, 2]
point = [0, -0.1, 0]
static_friction = 0.8
dynamic_friction = 0.6
compliance = 1e-6

[[collider]]
type = "sphere"
center = [1, 2, 3]
radius = 0.25

[[collider]]
type = "box"
center = [0, 0.5, 0]
half_extents = [0.1, 0.2, 0.3]
rotation = [90, 90, 0]

[hand]
enabled = false
model = "pro"
contact = "particles"
fingertip_radius = 0.012
compliance = 1e-5
grasp = "paper"
release_opening = 0.02
closing_speed = 0.05
hold_reach = 2
hold_compliance = 1e-4

[[hand.action]]
type = "poke"
body = "liver"
finger = "middle"
start = 0.5
approach = 1.5
hold = 0
release = 0.75
depth = 0.02
offset = [0.01, 0, -0.02]

[[hand.action]]
type = "grasp"
body = "flag"
finger = "little"
start = 4
approach = 2
hold = 1.25
release = 0.5
depth = 0.005
width = 0.05
lift = 0.1

[haptics]
calibrate = false
alpha = 0.3
beta_contact = 0.6
beta_volume = 0.7
beta_strain = 0.3
epsilon = 0.002
tau_contact = 2
tau_finger_contact = 3
tau_volume = 4
tau_strain = 5
max_change_per_ms = 0.1
baseline_contact_force = 0.4
baseline_stiffness = 50

[output]
mesh_every = 0.05
plots = false
)";

constexpr const char* kMinimal = R"([[body]]
mesh = "liver_coarse.obj"
)";

bool near(const Vec3& a, const Vec3& b) { return (a - b).norm() < 1e-6f; }

TEST(SceneFile, FullSceneSetsEveryField) {
  const SceneSpec s = parse(kFullScene);
  EXPECT_EQ(s.name, "liver-demo");
  EXPECT_EQ(s.description, "A liver poked and a flag pinched");
  EXPECT_EQ(s.source, "scene.toml");
  EXPECT_EQ(s.settle, 0.5);
  EXPECT_FALSE(s.settleToRest);
  EXPECT_EQ(s.seconds, 3.0);
  EXPECT_EQ(s.wind, Vec3(20, 0, 1.5f));

  EXPECT_DOUBLE_EQ(s.solver.timeStep, 1.0 / 120.0);
  EXPECT_EQ(s.solver.substeps, 4);
  EXPECT_EQ(s.solver.iterations, 8);
  EXPECT_EQ(s.solver.gravity, Vec3(0, -9.8f, 0.5f));
  EXPECT_FLOAT_EQ(s.solver.linearDamping, 0.2f);
  EXPECT_EQ(s.solver.simd, SimdLevel::Off);
  EXPECT_EQ(s.solver.threads, 2);
  EXPECT_FALSE(s.solver.fuseStrainVolume);
  EXPECT_FALSE(s.solver.measureResiduals);
  EXPECT_FLOAT_EQ(s.solver.tolerance, 1e-3f);

  ASSERT_EQ(s.bodies.size(), 3u);
  const BodySpec& liver = s.bodies[0];
  EXPECT_EQ(liver.name, "liver");
  EXPECT_EQ(liver.kind, BodyKind::Soft);
  EXPECT_EQ(liver.mesh, meshPath("liver_coarse.obj"));
  EXPECT_EQ(liver.renderMesh, meshPath("liver.obj"));  // lexically normal: no "orig/.."
  EXPECT_FLOAT_EQ(liver.scale, 0.01f);
  EXPECT_EQ(liver.rotationDeg, (std::array<float, 3>{90, 0, -45}));
  EXPECT_EQ(liver.position, Vec3(0.1f, 0.2f, -0.3f));
  EXPECT_EQ(liver.placement, Placement::AsIs);
  EXPECT_EQ(liver.mesher.mesher, Mesher::TetGen);
  EXPECT_EQ(liver.mesher.targetTets, 1500u);
  EXPECT_TRUE(liver.constraints.edges);
  EXPECT_FALSE(liver.constraints.volume);
  EXPECT_FALSE(liver.constraints.strain);
  EXPECT_TRUE(liver.constraints.shapeMatching);
  EXPECT_EQ(liver.force, Vec3(0, -1, 0));

  const Material& lm = liver.material;
  ASSERT_TRUE(lm.elastic.has_value());
  EXPECT_FLOAT_EQ(lm.elastic->youngsModulus, 5000.0f);
  EXPECT_FLOAT_EQ(lm.elastic->poissonRatio, 0.45f);
  EXPECT_FLOAT_EQ(lm.elastic->density, 1060.0f);
  EXPECT_FLOAT_EQ(lm.elastic->rayleighDamping, 0.01f);
  EXPECT_FLOAT_EQ(lm.particleRadius, 0.002f);
  // Blanket compliance 0.2 and damping 0.04, overridden per type.
  EXPECT_FLOAT_EQ(lm.distance.compliance, 0.2f);
  EXPECT_FLOAT_EQ(lm.distance.damping, 0.04f);
  EXPECT_FLOAT_EQ(lm.volume.compliance, 0.1f);
  EXPECT_FLOAT_EQ(lm.volume.damping, 0.04f);
  EXPECT_FLOAT_EQ(lm.strainStretch.compliance, 0.2f);
  EXPECT_FLOAT_EQ(lm.strainStretch.damping, 0.05f);
  EXPECT_FLOAT_EQ(lm.strainShear.compliance, 0.15f);
  EXPECT_FLOAT_EQ(lm.strainShear.damping, 0.02f);
  EXPECT_FLOAT_EQ(lm.shapeMatching.compliance, 0.5f);
  EXPECT_FLOAT_EQ(lm.shapeMatching.damping, 0.04f);
  EXPECT_FLOAT_EQ(lm.bending.compliance, 0.2f);

  const BodySpec& flag = s.bodies[1];
  EXPECT_EQ(flag.name, "flag");
  EXPECT_EQ(flag.kind, BodyKind::Cloth);
  EXPECT_EQ(flag.mesh, meshPath("flag_plane.obj"));
  EXPECT_EQ(flag.placement, Placement::Ground);
  EXPECT_EQ(flag.pin, (std::vector<std::string>{"-x", "+y"}));
  EXPECT_FLOAT_EQ(flag.pinTolerance, 0.01f);
  const Material& fm = flag.material;
  EXPECT_FALSE(fm.elastic.has_value());
  ASSERT_TRUE(fm.particleMass.has_value());
  EXPECT_FLOAT_EQ(*fm.particleMass, 0.05f);
  EXPECT_FLOAT_EQ(fm.distance.compliance, 2e-4f);
  EXPECT_FLOAT_EQ(fm.distance.damping, 0.01f);
  EXPECT_FLOAT_EQ(fm.bending.compliance, 1e-4f);
  EXPECT_FLOAT_EQ(fm.bending.damping, 0.06f);
  EXPECT_FLOAT_EQ(fm.volume.damping, 0.0f);

  const BodySpec& bunny = s.bodies[2];
  EXPECT_EQ(bunny.name, "body3");
  EXPECT_EQ(bunny.mesher.mesher, Mesher::Builtin);
  EXPECT_EQ(bunny.mesher.maxVolume, 1e-6);
  EXPECT_EQ(bunny.mesher.targetTets, 0u);

  ASSERT_EQ(s.colliders.size(), 3u);
  const Collider& plane = s.colliders[0];
  EXPECT_EQ(plane.shape, ColliderShape::Plane);
  EXPECT_EQ(plane.normal, Vec3(0, 0, 1));
  EXPECT_EQ(plane.center, Vec3(0, -0.1f, 0));
  EXPECT_FLOAT_EQ(plane.staticFriction, 0.8f);
  EXPECT_FLOAT_EQ(plane.dynamicFriction, 0.6f);
  EXPECT_FLOAT_EQ(plane.compliance, 1e-6f);
  const Collider& sphere = s.colliders[1];
  EXPECT_EQ(sphere.shape, ColliderShape::Sphere);
  EXPECT_EQ(sphere.center, Vec3(1, 2, 3));
  EXPECT_FLOAT_EQ(sphere.radius, 0.25f);
  const Collider& box = s.colliders[2];
  EXPECT_EQ(box.shape, ColliderShape::Box);
  EXPECT_EQ(box.center, Vec3(0, 0.5f, 0));
  EXPECT_EQ(box.halfExtents, Vec3(0.1f, 0.2f, 0.3f));
  // About x, then y: y -> z -> x, and x -> x -> -z. The other order would send y to z.
  EXPECT_TRUE(near(box.rotation * Vec3::UnitY(), Vec3::UnitX())) << box.rotation;
  EXPECT_TRUE(near(box.rotation * Vec3::UnitX(), -Vec3::UnitZ())) << box.rotation;

  const HandSpec& hand = s.hand;
  EXPECT_FALSE(hand.enabled);
  EXPECT_EQ(hand.rig.fingers, (std::array<bool, kFingerCount>{true, true, true, true, true}));
  EXPECT_EQ(hand.rig.contact, FingertipContactMode::Particles);
  EXPECT_FLOAT_EQ(hand.rig.geometry.fingertipRadius, 0.012f);
  EXPECT_FLOAT_EQ(hand.rig.compliance, 1e-5f);
  EXPECT_TRUE(hand.grasp.enabled);
  EXPECT_EQ(hand.grasp.mode, GraspMode::Paper);
  EXPECT_FLOAT_EQ(hand.grasp.releaseOpening, 0.02f);
  EXPECT_FLOAT_EQ(hand.grasp.closingSpeed, 0.05f);
  EXPECT_FLOAT_EQ(hand.grasp.holdReach, 2.0f);
  EXPECT_FLOAT_EQ(hand.grasp.holdCompliance, 1e-4f);
  EXPECT_EQ(hand.script, "");
  ASSERT_EQ(hand.actions.size(), 2u);
  const ActionSpec& poke = hand.actions[0];
  EXPECT_EQ(poke.action.kind, ActionKind::Poke);
  EXPECT_EQ(poke.body, "liver");
  EXPECT_EQ(poke.action.finger, Finger::Middle);
  EXPECT_EQ(poke.action.start, 0.5);
  EXPECT_EQ(poke.action.approach, 1.5);
  EXPECT_EQ(poke.action.hold, 0.0);
  EXPECT_EQ(poke.action.release, 0.75);
  EXPECT_FLOAT_EQ(poke.action.depth, 0.02f);
  EXPECT_EQ(poke.offset, Vec3(0.01f, 0, -0.02f));
  const ActionSpec& grasp = hand.actions[1];
  EXPECT_EQ(grasp.action.kind, ActionKind::Grasp);
  EXPECT_EQ(grasp.body, "flag");
  EXPECT_EQ(grasp.action.finger, Finger::Little);
  EXPECT_EQ(grasp.action.start, 4.0);
  EXPECT_EQ(grasp.action.approach, 2.0);
  EXPECT_EQ(grasp.action.hold, 1.25);
  EXPECT_EQ(grasp.action.release, 0.5);
  EXPECT_FLOAT_EQ(grasp.action.depth, 0.005f);
  EXPECT_FLOAT_EQ(grasp.action.width, 0.05f);
  EXPECT_FLOAT_EQ(grasp.action.lift, 0.1f);

  const HapticSettings& h = s.haptics.settings;
  EXPECT_FALSE(s.haptics.calibrate);
  EXPECT_FLOAT_EQ(h.signal.alphaT, 0.3f);
  EXPECT_FLOAT_EQ(h.signal.betaContact, 0.6f);
  EXPECT_FLOAT_EQ(h.signal.betaVolume, 0.7f);
  EXPECT_FLOAT_EQ(h.signal.betaStrain, 0.3f);
  EXPECT_FLOAT_EQ(h.signal.epsilon, 0.002f);
  EXPECT_FLOAT_EQ(h.signal.tauContact, 2.0f);
  EXPECT_FLOAT_EQ(h.signal.tauFingerContact, 3.0f);
  EXPECT_FLOAT_EQ(h.signal.tauVolume, 4.0f);
  EXPECT_FLOAT_EQ(h.signal.tauStrain, 5.0f);
  EXPECT_FLOAT_EQ(h.maxChangePerMs, 0.1f);
  EXPECT_FLOAT_EQ(h.baseline.contactForce, 0.4f);
  EXPECT_FLOAT_EQ(h.baseline.stiffness, 50.0f);

  EXPECT_EQ(s.output.meshEvery, 0.05);
  EXPECT_FALSE(s.output.plots);
}

TEST(SceneFile, AbsentKeysKeepTheirDefaults) {
  const SceneSpec s = parse(std::string(kMinimal) + "[[hand.action]]\ntype = \"poke\"\n");
  const SceneSpec d;
  EXPECT_EQ(s.name, "scene");  // the file's stem
  EXPECT_EQ(s.description, "");
  EXPECT_TRUE(s.settleToRest);  // until at rest, at most:
  EXPECT_EQ(s.settle, SceneSpec::kSettleToRestMost);
  EXPECT_EQ(s.seconds, 6.0);
  EXPECT_EQ(s.wind, Vec3::Zero());
  EXPECT_EQ(s.solver.timeStep, d.solver.timeStep);
  EXPECT_EQ(s.solver.substeps, 8);  // the scenes' default: the paper's 1 loses volume while settling
  EXPECT_EQ(s.solver.iterations, d.solver.iterations);
  EXPECT_EQ(s.solver.gravity, d.solver.gravity);
  EXPECT_EQ(s.solver.simd, SimdLevel::Best);
  EXPECT_EQ(s.solver.threads, SolverSettings::kAutoThreads);
  EXPECT_TRUE(s.solver.fuseStrainVolume);
  EXPECT_TRUE(s.solver.measureResiduals);  // the scenes' default, unlike SolverSettings'
  EXPECT_EQ(s.solver.tolerance, 0.0f);

  ASSERT_EQ(s.bodies.size(), 1u);
  const BodySpec& b = s.bodies[0];
  EXPECT_EQ(b.name, "body1");
  EXPECT_EQ(b.kind, BodyKind::Soft);
  EXPECT_EQ(b.mesh, meshPath("liver_coarse.obj"));
  EXPECT_EQ(b.renderMesh, "");
  EXPECT_EQ(b.scale, 1.0f);
  EXPECT_EQ(b.placement, Placement::Ground);
  EXPECT_EQ(b.mesher.mesher, Mesher::Builtin);
  EXPECT_EQ(b.mesher.targetTets, 0u);
  const ConstraintSet paper = ConstraintSet::paper();
  EXPECT_EQ(b.constraints.edges, paper.edges);
  EXPECT_EQ(b.constraints.volume, paper.volume);
  EXPECT_EQ(b.constraints.strain, paper.strain);
  EXPECT_EQ(b.constraints.shapeMatching, paper.shapeMatching);
  ASSERT_TRUE(b.material.elastic.has_value());  // soft tissue
  EXPECT_EQ(b.material.elastic->youngsModulus, 3.0e4f);
  EXPECT_EQ(b.material.elastic->poissonRatio, 0.45f);
  EXPECT_EQ(b.material.elastic->density, 1060.0f);
  EXPECT_EQ(b.material.elastic->rayleighDamping, 0.005f);
  EXPECT_FALSE(b.material.particleMass.has_value());  // masses from the density
  ASSERT_EQ(s.colliders.size(), 1u);                  // the ground
  EXPECT_EQ(s.colliders[0].shape, ColliderShape::Plane);
  EXPECT_EQ(s.colliders[0].normal, Vec3::UnitY());
  EXPECT_EQ(s.colliders[0].center, Vec3::Zero());

  EXPECT_TRUE(s.hand.enabled);
  EXPECT_FALSE(s.hand.rig.fingers[int(Finger::Ring)]);  // g1
  EXPECT_EQ(s.hand.rig.contact, FingertipContactMode::Triangles);
  EXPECT_EQ(s.hand.rig.friction.staticFriction, 0.8f);  // skin, unlike HandRigSettings' frictionless
  EXPECT_EQ(s.hand.rig.friction.dynamicFriction, 0.6f);
  EXPECT_TRUE(s.hand.grasp.enabled);
  EXPECT_EQ(s.hand.grasp.mode, GraspMode::Local);
  ASSERT_EQ(s.hand.actions.size(), 1u);
  const ActionSpec& a = s.hand.actions[0];
  const ActionSpec da;
  EXPECT_EQ(a.body, "");
  EXPECT_EQ(a.action.finger, Finger::Index);
  EXPECT_EQ(a.action.start, da.action.start);
  EXPECT_EQ(a.action.approach, da.action.approach);
  EXPECT_EQ(a.action.depth, da.action.depth);

  EXPECT_TRUE(s.haptics.calibrate);
  EXPECT_EQ(s.haptics.settings.maxChangePerMs, HapticSettings().maxChangePerMs);
  EXPECT_EQ(s.haptics.settings.signal.betaVolume, 0.5f);
  EXPECT_EQ(s.output.meshEvery, d.output.meshEvery);
  EXPECT_TRUE(s.output.plots);
}

TEST(SceneFile, DtSetsTheTimeStepAndIntegersServeAsFloats) {
  const SceneSpec s = parse(std::string(kMinimal) + "[solver]\ndt = 0.002\nlinear_damping = 1\n");
  EXPECT_DOUBLE_EQ(s.solver.timeStep, 0.002);
  EXPECT_EQ(s.solver.linearDamping, 1.0f);
}

TEST(SceneFile, OneBetaGivesTheOther) {
  EXPECT_FLOAT_EQ(parse(std::string(kMinimal) + "[haptics]\nbeta_volume = 0.8\n").haptics.settings.signal.betaStrain,
                  0.2f);
  EXPECT_FLOAT_EQ(parse(std::string(kMinimal) + "[haptics]\nbeta_strain = 0.9\n").haptics.settings.signal.betaVolume,
                  0.1f);
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[haptics]\nbeta_volume = 0.5\nbeta_strain = 0.3\n"),
            "scene.toml:5: haptics.beta_strain: beta_volume + beta_strain must be 1, got 0.8");
}

TEST(SceneFile, MaxChangeMayBeInfinite) {
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(parse(std::string(kMinimal) + "[haptics]\nmax_change_per_ms = \"inf\"\n").haptics.settings.maxChangePerMs,
            inf);
  EXPECT_EQ(parse(std::string(kMinimal) + "[haptics]\nmax_change_per_ms = inf\n").haptics.settings.maxChangePerMs, inf);
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[haptics]\nmax_change_per_ms = \"fast\"\n"),
            "scene.toml:4: haptics.max_change_per_ms: expected a number or \"inf\", got 'fast'");
}

TEST(SceneFile, TheGroundIsThereUnlessTheSceneHasCollidersOrTurnsItOff) {
  EXPECT_EQ(parse(std::string(kMinimal)).colliders.size(), 1u);
  EXPECT_TRUE(parse("ground = false\n" + std::string(kMinimal)).colliders.empty());
  const SceneSpec own = parse(std::string(kMinimal) + "[[collider]]\ntype = \"sphere\"\nradius = 1\n");
  ASSERT_EQ(own.colliders.size(), 1u);
  EXPECT_EQ(own.colliders[0].shape, ColliderShape::Sphere);
}

TEST(SceneFile, ThreadsMayBeAuto) {
  EXPECT_EQ(parse(std::string(kMinimal) + "[solver]\nthreads = \"auto\"\n").solver.threads,
            SolverSettings::kAutoThreads);
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[solver]\nthreads = \"many\"\n"),
            "scene.toml:4: solver.threads: expected an integer or \"auto\", got 'many'");
  EXPECT_NE(errorIn(std::string(kMinimal) + "[solver]\nthreads = 0\n").find("solver.threads"), std::string::npos);
}

TEST(SceneFile, GraspOffDisablesGrasping) {
  const SceneSpec s = parse(std::string(kMinimal) + "[hand]\ngrasp = \"off\"\n");
  EXPECT_FALSE(s.hand.grasp.enabled);
}

TEST(SceneFile, LoadSceneTakesPathsFromTheFilesFolder) {
  const testing::TempDir dir;
  fs::create_directories(dir / "meshes");
  writeText(dir / "meshes" / "cube.obj", "v 0 0 0\n");
  writeText(dir / "poke.hand", "vrdeform-hand-script 1\n0 0 0 0 1 0 0 0 0 0 0\n");
  writeText(dir / "demo.toml", "[[body]]\nmesh = \"meshes/./cube.obj\"\n[hand]\nscript = \"poke.hand\"\n");
  const SceneSpec s = loadScene(dir / "demo.toml");
  EXPECT_EQ(s.name, "demo");
  EXPECT_EQ(s.source, (dir / "demo.toml").string());
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.bodies[0].mesh, (dir / "meshes" / "cube.obj").string());
  EXPECT_EQ(s.hand.script, (dir / "poke.hand").string());
}

TEST(SceneFile, LoadSceneOfMissingFileSaysWhy) {
  const testing::TempDir dir;
  const fs::path missing = dir / "none.toml";
  EXPECT_EQ(errorOf([&] { loadScene(missing); }), missing.string() + ": cannot read: No such file or directory");
  EXPECT_EQ(errorOf([&] { loadScene(dir.path()); }), dir.path().string() + ": cannot read: not a regular file");
}

TEST(SceneFile, LoadSceneReportsErrorsUnderTheGivenName) {
  const testing::TempDir dir;
  writeText(dir / "bad.toml", "[[body]]\nmesh = 3\n");
  EXPECT_EQ(errorOf([&] { loadScene(dir / "bad.toml"); }),
            (dir / "bad.toml").string() + ":2: body[1].mesh: expected a string, got an integer");
}

TEST(SceneFile, DocumentedExampleParses) {
  // docs/scenes.md's complete example, whose meshes sit next to it.
  std::ifstream in(VRDEFORM_TEST_DATA_DIR "/../docs/scenes.md");
  const std::string doc{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t begin = doc.find("```toml\n");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  const SceneSpec s = parse(doc.substr(begin + 8, end - begin - 8));
  EXPECT_EQ(s.name, "liver-and-flag");
  EXPECT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(s.colliders.size(), 2u);
  EXPECT_EQ(s.hand.actions.size(), 2u);
}

// --- One test per kind of error, each with its exact "file:line: key:" ---

TEST(SceneFile, SyntaxErrorGivesLineAndTomlReason) {
  const std::string e = errorIn(R"([[body]]
mesh = "liver_coarse.obj"
scale = = 2
)");
  EXPECT_TRUE(e.starts_with("scene.toml:3: TOML syntax: ")) << e;
  EXPECT_GT(e.size(), std::string("scene.toml:3: TOML syntax: ").size()) << e;
}

TEST(SceneFile, UnknownKeySuggestsTheCloseOne) {
  EXPECT_EQ(errorIn(R"([[body]]
meshh = "liver_coarse.obj"
)"),
            "scene.toml:2: body[1].meshh: unknown key (did you mean 'mesh'?)");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[solver]\nitreations = 3\n"),
            "scene.toml:4: solver.itreations: unknown key (did you mean 'iterations'?)");
}

TEST(SceneFile, UnknownKeyFarFromAnyListsTheKnownOnes) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material.distance]\nstiffness = 3\n"),
            "scene.toml:4: body[1].material.distance.stiffness: unknown key (expected one of: compliance, damping)");
  // The first unknown key in the file's order, though toml++ keeps a table's keys sorted.
  const std::string e = errorIn("zebra = 1\ncolour = 2\n" + std::string(kMinimal));
  EXPECT_TRUE(e.starts_with("scene.toml:1: zebra: unknown key (expected one of: format, name,")) << e;
}

TEST(SceneFile, KeyOfAnotherKindIsRejected) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[collider]]\ntype = \"plane\"\nradius = 1\n"),
            "scene.toml:5: collider[1].radius: does not apply to a plane collider");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "pin = [\"-x\"]\n"),
            "scene.toml:3: body[1].pin: does not apply to a soft body");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[hand.action]]\ntype = \"poke\"\nlift = 0.01\n"),
            "scene.toml:5: hand.action[1].lift: does not apply to a poke");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[hand.action]]\ntype = \"grasp\"\nprofile = \"linear\"\n"),
            "scene.toml:5: hand.action[1].profile: does not apply to a grasp");
  const SceneSpec linear = parse(std::string(kMinimal) + "[[hand.action]]\ntype = \"poke\"\nprofile = \"linear\"\n");
  EXPECT_EQ(linear.hand.actions[0].action.profile, PokeProfile::Linear);
  EXPECT_EQ(parse(std::string(kMinimal) + "[[hand.action]]\ntype = \"poke\"\n").hand.actions[0].action.profile,
            PokeProfile::MinimumJerk);
}

TEST(SceneFile, WrongTypeNamesBoth) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\nyoungs = \"5000\"\npoisson = 0.4\ndensity = 1000\n"),
            "scene.toml:4: body[1].material.youngs: expected a number, got a string");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[solver]\nsubsteps = 2.0\n"),
            "scene.toml:4: solver.substeps: expected an integer, got a float");
  EXPECT_EQ(errorIn("[body]\nmesh = \"liver_coarse.obj\"\n"),
            "scene.toml:1: body: expected an array of tables ([[body]]), got a table");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[solver]\nsimd = 1\n"),
            "scene.toml:4: solver.simd: expected a boolean (true or false), got an integer");
}

TEST(SceneFile, MissingMeshIsReportedAtTheBodysHeader) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "\n[[body]]\nname = \"b\"\n"), "scene.toml:4: body[2].mesh: missing");
  EXPECT_EQ(errorIn("name = \"empty\"\n"), "scene.toml:1: body: missing (a scene needs at least one [[body]])");
}

TEST(SceneFile, MeshFileNotFoundGivesTheAbsolutePath) {
  EXPECT_EQ(errorIn("[[body]]\nmesh = \"sub/../nope.obj\"\n"),
            "scene.toml:2: body[1].mesh: no such file '" + meshPath("nope.obj") + "'");
  EXPECT_EQ(errorIn("[[body]]\nmesh = \"tet\"\n"),
            "scene.toml:2: body[1].mesh: '" + meshPath("tet") + "' is not a regular file");
}

TEST(SceneFile, NegativeDtIsOutOfRange) {
  EXPECT_EQ(errorIn("[solver]\ndt = -0.01\n" + std::string(kMinimal)),
            "scene.toml:2: solver.dt: must be positive, got -0.01");
  EXPECT_EQ(errorIn("[solver]\nrate = 0\n" + std::string(kMinimal)),
            "scene.toml:2: solver.rate: must be in 1..100000, got 0");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\npoisson = 0.5\nyoungs = 1e4\ndensity = 1000\n"),
            "scene.toml:4: body[1].material.poisson: must be in [0, 0.5), got 0.5");
}

TEST(SceneFile, RateAndDtTogetherNameTheSecond) {
  EXPECT_EQ(errorIn("[solver]\ndt = 0.01\nrate = 60\n" + std::string(kMinimal)),
            "scene.toml:3: solver.rate: give either rate or dt, not both");
  EXPECT_EQ(errorIn("[solver]\nrate = 60\ndt = 0.01\n" + std::string(kMinimal)),
            "scene.toml:3: solver.dt: give either rate or dt, not both");
}

TEST(SceneFile, UnknownEnumValueListsTheAllowedOnes) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "kind = \"sofft\"\n"),
            "scene.toml:3: body[1].kind: unknown value 'sofft' (expected one of: soft, cloth)");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "constraints = [\"volume\", \"stran\"]\n"),
            "scene.toml:3: body[1].constraints[2]: unknown value 'stran' (expected one of: edges, volume, strain, "
            "shape_matching)");
}

TEST(SceneFile, ModuliGoTogether) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\nyoungs = 1e4\ndensity = 1000\n"),
            "scene.toml:3: body[1].material.poisson: missing (youngs, poisson and density go together)");
  EXPECT_EQ(errorIn(std::string(kMinimal) +
                    "[body.material]\nyoungs = 1e4\npoisson = 0.3\ndensity = 1000\nparticle_mass = 0.1\n"),
            "scene.toml:7: body[1].material.particle_mass: cannot go with moduli: the density gives the masses");
  EXPECT_EQ(errorIn("[[body]]\nkind = \"cloth\"\nmesh = \"flag_plane.obj\"\n"
                    "[body.material]\nyoungs = 1e4\npoisson = 0.3\ndensity = 1000\n"),
            "scene.toml:5: body[1].material.youngs: a cloth takes compliance and damping, not moduli");
}

TEST(SceneFile, MassesComeFromADensityOrAParticleMass) {
  // Soft tissue of another density; the paper's compliance form with a density.
  const Material soft = parse(std::string(kMinimal) + "[body.material]\ndensity = 500\n").bodies[0].material;
  ASSERT_TRUE(soft.elastic.has_value());
  EXPECT_FLOAT_EQ(soft.elastic->density, 500.0f);
  const Material paper =
      parse(std::string(kMinimal) + "[body.material]\ndensity = 500\ncompliance = 0.3\n").bodies[0].material;
  EXPECT_FALSE(paper.elastic.has_value());
  EXPECT_FLOAT_EQ(paper.density, 500.0f);
  const std::string cloth = "[[body]]\nkind = \"cloth\"\nmesh = \"flag_plane.obj\"\n[body.material]\n";
  EXPECT_FLOAT_EQ(parse(cloth + "areal_density = 0.3\n").bodies[0].material.arealDensity, 0.3f);
  EXPECT_EQ(errorIn(cloth + "density = 500\n"),
            "scene.toml:5: body[1].material.density: a cloth's masses come from areal_density (kg/m^2)");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\nareal_density = 0.3\n"),
            "scene.toml:4: body[1].material.areal_density: a soft body's masses come from density (kg/m^3)");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\ndensity = 500\nparticle_mass = 0.1\n"),
            "scene.toml:5: body[1].material.particle_mass: cannot go with density: one of them gives the masses");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.material]\ndensity = 0\n"),
            "scene.toml:4: body[1].material.density: must be positive, got 0");
}

TEST(SceneFile, ActionNamingAnUnknownBody) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "name = \"liver\"\n[[hand.action]]\ntype = \"poke\"\nbody = \"livr\"\n"),
            "scene.toml:6: hand.action[1].body: no body named 'livr' (the bodies: liver)");
}

TEST(SceneFile, FingerTheHandLacks) {
  const std::string ring = "[[hand.action]]\ntype = \"poke\"\nfinger = \"ring\"\n";
  EXPECT_EQ(errorIn(std::string(kMinimal) + ring),
            "scene.toml:5: hand.action[1].finger: the g1 hand has no ring fingertip (model = \"pro\" has all five)");
  EXPECT_EQ(parse(std::string(kMinimal) + "[hand]\nmodel = \"pro\"\n" + ring).hand.actions[0].action.finger,
            Finger::Ring);
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[hand.action]]\ntype = \"grasp\"\nfinger = \"thumb\"\n"),
            "scene.toml:5: hand.action[1].finger: a grasp pairs the thumb with another finger; name that finger "
            "(index, middle, ring or little)");
}

TEST(SceneFile, NanAndInfinityAreRejected) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "scale = nan\n"),
            "scene.toml:3: body[1].scale: must be a finite number, got nan");
  EXPECT_EQ(errorIn("wind = [0, -inf, 0]\n" + std::string(kMinimal)),
            "scene.toml:1: wind[2]: must be a finite number, got -inf");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "scale = 1e40\n"),
            "scene.toml:3: body[1].scale: is out of range, got 1e+40");
}

TEST(SceneFile, VectorsHaveThreeNumbers) {
  EXPECT_EQ(errorIn(std::string(kMinimal) + "position = [1, 2]\n"),
            "scene.toml:3: body[1].position: expected an array of 3 numbers, got 2 of them");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "position = [1,\n  \"2\",\n  3]\n"),
            "scene.toml:4: body[1].position[2]: expected a number, got a string");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "position = 1\n"),
            "scene.toml:3: body[1].position: expected an array of 3 numbers, got an integer");
}

TEST(SceneFile, BodyNamesAreUnique) {
  EXPECT_EQ(
      errorIn("[[body]]\nname = \"liver\"\nmesh = \"liver.obj\"\n[[body]]\nname = \"liver\"\nmesh = \"liver.obj\"\n"),
      "scene.toml:5: body[2].name: 'liver' is also the name of body[1]");
  // A default name counts too; then the line is the body's header.
  EXPECT_EQ(errorIn("[[body]]\nname = \"body2\"\nmesh = \"liver.obj\"\n[[body]]\nmesh = \"liver.obj\"\n"),
            "scene.toml:4: body[2].name: 'body2' is also the name of body[1]");
}

TEST(SceneFile, FormatOtherThanOneIsRejected) {
  EXPECT_EQ(errorIn("format = 2\n" + std::string(kMinimal)),
            "scene.toml:1: format: this vrdeform reads format 1, got 2");
}

TEST(SceneFile, LibraryValidatorErrorsGetTheTablesLine) {
  // A normal whose length overflows a float passes the parser's non-zero check and is caught by
  // validateCollider.
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[collider]]\ntype = \"plane\"\nnormal = [3e38, 3e38, 0]\n"),
            "scene.toml:3: collider[1]: a plane needs a finite, non-zero normal");
}

TEST(SceneFile, ScriptAndActionsExcludeEachOther) {
  const testing::TempDir dir;
  writeText(dir / "poke.hand", "vrdeform-hand-script 1\n");
  writeText(dir / "m.obj", "v 0 0 0\n");
  const std::string text =
      "[[body]]\nmesh = \"m.obj\"\n[hand]\nscript = \"poke.hand\"\n[[hand.action]]\ntype = \"poke\"\n";
  EXPECT_EQ(errorOf([&] { parseScene(text, "s.toml", dir.path()); }),
            "s.toml:4: hand.script: a script replaces the [[hand.action]] list; give one or the other");
}

TEST(SceneFile, GarbageAndInvalidUtf8AreSyntaxErrors) {
  EXPECT_TRUE(errorIn("\xff\xfe[[body]]\n").starts_with("scene.toml:1: TOML syntax: "));
  EXPECT_TRUE(errorIn(std::string(kMinimal) + "name = \"caf\xc3\"\n").starts_with("scene.toml:3: TOML syntax: "));
  const std::string withNul = std::string(kMinimal) + std::string("name = \"a\0b\"\n", 13);
  EXPECT_TRUE(errorIn(withNul).starts_with("scene.toml:3: ")) << errorIn(withNul);
  // Control characters in a quoted key come back escaped.
  EXPECT_EQ(errorIn(std::string(kMinimal) + "\"a\\u0001\" = 1\n"),
            "scene.toml:3: body[1].a\\x01: unknown key (expected one of: name, kind, mesh, scale, rotation, position, "
            "placement, force, material, on, contact, render_mesh, mesher, tets, max_volume, constraints)");

  std::mt19937 rng(7);
  for (int i = 0; i < 300; ++i) {
    std::string bytes(rng() % 200, '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    try {
      parse(bytes);
      ADD_FAILURE() << "random bytes parsed as a scene";
    } catch (const Error&) {
    }
  }
}

TEST(SceneFile, DeeplyNestedKeysAreRefusedNotACrash) {
  // toml++ recurses per level of a dotted key; 100000 levels overflowed the stack before the cap.
  std::string deep = "a";
  for (int i = 0; i < 10000; ++i) deep += ".a";
  EXPECT_TRUE(errorIn(deep + " = 1\n").starts_with("scene.toml:1: a: unknown key"));
  for (int i = 0; i < 90000; ++i) deep += ".a";
  EXPECT_EQ(errorIn("\n" + deep + " = 1\n"),
            "scene.toml:2: TOML syntax: more than 10000 dots; keys may nest too deep to parse safely");
  EXPECT_TRUE(errorIn("[" + deep + "]\n").starts_with("scene.toml:1: TOML syntax: more than 10000 dots"));
  EXPECT_TRUE(errorIn("x = " + std::string(100000, '[')).starts_with("scene.toml:1: TOML syntax: "));
}

TEST(SceneFile, EditedScenesParseOrFailWithAnError) {
  // Random edits of a valid scene: each either parses or throws vrd::Error "scene.toml:LINE: ...";
  // nothing crashes and no other exception escapes.
  std::mt19937 rng(11);
  int failures = 0;
  for (int i = 0; i < 2000; ++i) {
    const std::string text = testing::mutate(kFullScene, rng, "[]{}\"'=.,#\n 0123456789-+eEinfa");
    try {
      parse(text);
    } catch (const Error& e) {
      ++failures;
      EXPECT_TRUE(std::string_view(e.what()).starts_with("scene.toml:")) << e.what();
    }
  }
  EXPECT_GT(failures, 0);
}

}  // namespace
}  // namespace vrd

namespace vrd {
namespace {

// Contact between bodies in a scene file: each body's [body.contact], a body placed `on` another,
// and pairs that pass through each other; a body `on` one that comes later, or a pair naming a
// body the scene lacks, is an error at its key.
TEST(SceneFile, ContactBetweenBodiesIsReadAndBuilt) {
  const SceneSpec s = parse(R"([[body]]
name = "pad"
mesh = "sphere_coarse.obj"
scale = 0.05
[body.contact]
self = true
thickness = 0.002
static_friction = 0.9
dynamic_friction = 0.7
[[body]]
name = "top"
mesh = "sphere_coarse.obj"
scale = 0.03
on = "pad"
[[body]]
name = "ghost"
mesh = "sphere_coarse.obj"
scale = 0.03
position = [0.2, 0, 0]
[body.contact]
bodies = false
[[no_contact]]
bodies = ["top", "ghost"]
)");
  ASSERT_EQ(s.bodies.size(), 3u);
  EXPECT_TRUE(s.bodies[0].contact.self);
  EXPECT_FLOAT_EQ(s.bodies[0].contact.thickness, 0.002f);
  EXPECT_FLOAT_EQ(s.bodies[0].contact.staticFriction, 0.9f);
  EXPECT_FALSE(s.bodies[1].contact.self);  // the defaults
  EXPECT_TRUE(s.bodies[1].contact.bodies);
  EXPECT_FALSE(s.bodies[2].contact.bodies);
  EXPECT_EQ(s.bodies[1].on, "pad");
  ASSERT_EQ(s.noContact.size(), 1u);
  EXPECT_EQ(s.noContact[0], (std::array<std::string, 2>{"top", "ghost"}));

  SceneSpec quick = s;
  quick.settle = 0.0;
  quick.haptics.calibrate = false;
  const BuiltScene scene = buildScene(quick);
  const World& w = *scene.world;
  EXPECT_TRUE(w.bodyContact(scene.body("pad").id).self);
  EXPECT_FALSE(w.bodyContact(scene.body("ghost").id).bodies);
  EXPECT_FALSE(w.pairContact(scene.body("top").id, scene.body("ghost").id));
  EXPECT_TRUE(w.pairContact(scene.body("pad").id, scene.body("top").id));
  // On the pad: the top's lowest point the two thicknesses above the pad's highest (0.002 + 0.001).
  float padTop = -1e9f, topBottom = 1e9f;
  for (Index i = 0; i < w.body(scene.body("pad").id).particleCount; ++i)
    padTop = std::max(padTop, w.particles().x[w.particleIndex(scene.body("pad").id, i)].pos.y());
  for (Index i = 0; i < w.body(scene.body("top").id).particleCount; ++i)
    topBottom = std::min(topBottom, w.particles().x[w.particleIndex(scene.body("top").id, i)].pos.y());
  EXPECT_NEAR(topBottom - padTop, 0.003f, 1e-5f);

  EXPECT_EQ(
      errorIn(std::string(kMinimal) + "on = \"later\"\n[[body]]\nname = \"later\"\nmesh = \"sphere_coarse.obj\"\n"),
      "scene.toml:3: body[1].on: no body 'later' before this one");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[no_contact]]\nbodies = [\"body1\", \"nobody\"]\n"),
            "scene.toml:4: no_contact[1].bodies: no body 'nobody'");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[[no_contact]]\nbodies = [\"body1\"]\n"),
            "scene.toml:4: no_contact[1].bodies: needs two body names, got 1");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.contact]\nthickness = -1\n"),
            "scene.toml:4: body[1].contact.thickness: must be >= 0, got -1");
  EXPECT_EQ(errorIn(std::string(kMinimal) + "[body.contact]\nselff = true\n"),
            "scene.toml:4: body[1].contact.selff: unknown key (did you mean 'self'?)");
}

}  // namespace
}  // namespace vrd
