// Scene files (docs/scenes.md): toml++ reads the TOML, this file checks it against the schema and
// fills a SceneSpec. People write these files by hand, so every message names the file, the line
// and the dotted key of the problem, and unknown keys are errors rather than silently ignored.
#include "vrdeform/scene/scene_file.h"

#include <algorithm>
#include <numbers>

#include "scene/scene_settings_tables.h"
#include "scene/toml_schema.h"

namespace vrd {
namespace {

using namespace schema;

// Scene files' defaults where the library keeps the paper's: 8 substeps (at the paper's 1 a soft
// body settling under gravity loses several percent of its volume, and more); fingertips with
// skin's friction (frictionless, a round body rolls away under the finger: docs/haptics.md); and
// soft tissue (the liver's) for a soft body whose material gives neither moduli nor compliances.
constexpr int kSceneSubsteps = 8;
constexpr FingertipFriction kSkin{0.8f, 0.6f};
constexpr ElasticModuli kSoftTissue{3.0e4f, 0.45f, 1060.0f, 0.005f};

// Rotation about x, then y, then z, in degrees: the order of BodySpec::rotationDeg.
Mat3 rotationFromDegrees(const Vec3& degrees) {
  const Vec3 r = degrees * float(std::numbers::pi / 180.0);
  return (Eigen::AngleAxisf(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisf(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisf(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

void readModuli(const Table& t, BodyKind kind, Material& m) {
  if (!t.has("youngs") && !t.has("poisson")) {
    if (t.has("rayleigh_damping")) t.fail("rayleigh_damping", "needs youngs, poisson and density");
    return;
  }
  for (std::string_view key : {"youngs", "poisson", "density"})
    if (!t.has(key)) t.fail(key, "missing (youngs, poisson and density go together)");
  if (kind == BodyKind::Cloth) t.fail("youngs", "a cloth takes compliance and damping, not moduli");
  if (t.has("particle_mass")) t.fail("particle_mass", "cannot go with moduli: the density gives the masses");
  ElasticModuli e{t.require("youngs").number<float>(kPositive),
                  t.require("poisson").number<float>(Range{0, 0.5, false, true}),
                  t.require("density").number<float>(kPositive)};
  t.readNumber("rayleigh_damping", e.rayleighDamping, kNonNegative);
  m.elastic = e;
}

// Masses: lumped from the density (soft) or areal density (cloth), or a fixed mass per particle.
void readMass(const Table& t, BodyKind kind, Material& m) {
  const bool cloth = kind == BodyKind::Cloth;
  if (cloth && t.has("density")) t.fail("density", "a cloth's masses come from areal_density (kg/m^2)");
  if (!cloth && t.has("areal_density")) t.fail("areal_density", "a soft body's masses come from density (kg/m^3)");
  if (t.has("particle_mass"))
    for (std::string_view key : {"density", "areal_density"})
      if (t.has(key)) t.fail("particle_mass", fmt::format("cannot go with {}: one of them gives the masses", key));
  t.readNumber("density", m.density, kPositive);
  t.readNumber("areal_density", m.arealDensity, kPositive);
  if (std::optional<Field> f = t.get("particle_mass")) m.particleMass = f->number<float>(kPositive);
}

// A soft body whose material table gives neither moduli nor the paper's compliance form: soft
// tissue (as the liver's), so that a scene of a mesh alone weighs and deforms as a body would.
bool takesSoftTissue(const Table& t, BodyKind kind) {
  if (kind != BodyKind::Soft) return false;
  for (std::string_view key : {"youngs", "poisson", "compliance", "damping", "particle_mass", "distance", "volume",
                               "strain_stretch", "strain_shear", "shape_matching", "bending"})
    if (t.has(key)) return false;
  return true;
}

Material readMaterial(const Table& t, BodyKind kind) {
  static constexpr Option<ConstraintMaterial Material::*> kTypes[] = {{"distance", &Material::distance},
                                                                      {"volume", &Material::volume},
                                                                      {"strain_stretch", &Material::strainStretch},
                                                                      {"strain_shear", &Material::strainShear},
                                                                      {"shape_matching", &Material::shapeMatching},
                                                                      {"bending", &Material::bending}};
  Keys keys = {"youngs",     "poisson", "density",       "areal_density",  "rayleigh_damping",
               "compliance", "damping", "particle_mass", "particle_radius"};
  for (const auto& type : kTypes) keys.push_back(type.name);
  t.allowOnly(keys);

  Material m;
  if (takesSoftTissue(t, kind)) {
    m.elastic = kSoftTissue;
    t.readNumber("density", m.elastic->density, kPositive);
    t.readNumber("rayleigh_damping", m.elastic->rayleighDamping, kNonNegative);
  } else {
    readModuli(t, kind, m);
  }
  readMass(t, kind, m);
  // The blanket values first, so that a type's own table overrides them.
  if (std::optional<Field> f = t.get("compliance"))
    for (const auto& type : kTypes) (m.*type.value).compliance = f->number<float>(kNonNegative);
  if (std::optional<Field> f = t.get("damping"))
    for (const auto& type : kTypes) (m.*type.value).damping = f->number<float>(kNonNegative);
  for (const auto& type : kTypes) {
    const Table sub = t.table(type.name);
    sub.allowOnly({"compliance", "damping"});
    sub.readNumber("compliance", (m.*type.value).compliance, kNonNegative);
    sub.readNumber("damping", (m.*type.value).damping, kNonNegative);
  }
  t.readNumber("particle_radius", m.particleRadius, kNonNegative);
  return m;
}

ConstraintSet readConstraints(const Field& f) {
  static constexpr Option<bool ConstraintSet::*> kNames[] = {{"edges", &ConstraintSet::edges},
                                                             {"volume", &ConstraintSet::volume},
                                                             {"strain", &ConstraintSet::strain},
                                                             {"shape_matching", &ConstraintSet::shapeMatching}};
  const std::vector<Field> names = f.elements("an array of strings");
  if (names.empty()) f.fail("must list at least one of: edges, volume, strain, shape_matching");
  ConstraintSet set{false, false, false, false};
  for (const Field& name : names) set.*name.choose(kNames) = true;
  return set;
}

std::vector<std::string> readPins(const Field& f) {
  static constexpr Option<std::string_view> kSides[] = {{"-x", "-x"}, {"+x", "+x"}, {"-y", "-y"},
                                                        {"+y", "+y"}, {"-z", "-z"}, {"+z", "+z"}};
  std::vector<std::string> pins;
  for (const Field& side : f.elements("an array of strings")) pins.emplace_back(side.choose(kSides));
  return pins;
}

BodyContactSettings readBodyContact(const Table& t) {
  t.allowOnly({"bodies", "self", "thickness", "static_friction", "dynamic_friction", "compliance"});
  BodyContactSettings c;
  t.readBool("bodies", c.bodies);
  t.readBool("self", c.self);
  t.readNumber("thickness", c.thickness, kNonNegative);
  t.readNumber("static_friction", c.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", c.dynamicFriction, kNonNegative);
  t.readNumber("compliance", c.compliance, kNonNegative);
  return c;
}

BodySpec readBody(const Table& t, std::size_t number) {
  static constexpr Option<BodyKind> kKinds[] = {{"soft", BodyKind::Soft}, {"cloth", BodyKind::Cloth}};
  static constexpr Option<Placement> kPlacements[] = {{"ground", Placement::Ground}, {"as_is", Placement::AsIs}};
  static constexpr Option<Mesher> kMeshers[] = {{"builtin", Mesher::Builtin}, {"tetgen", Mesher::TetGen}};
  static const Keys kCommon = {"name",      "kind",  "mesh",     "scale", "rotation", "position",
                               "placement", "force", "material", "on",    "contact"};
  static const Keys kSoftOnly = {"render_mesh", "mesher", "tets", "max_volume", "constraints"};
  static const Keys kClothOnly = {"pin", "pin_tolerance"};

  BodySpec body;
  t.readChoice("kind", body.kind, kKinds);
  const bool soft = body.kind == BodyKind::Soft;
  t.allowOnly(concat(kCommon, soft ? kSoftOnly : kClothOnly), soft ? kClothOnly : kSoftOnly,
              soft ? "a soft body" : "a cloth");

  body.name = fmt::format("body{}", number);
  if (std::optional<Field> f = t.get("name")) body.name = f->name();
  body.mesh = t.require("mesh").file();
  if (std::optional<Field> f = t.get("render_mesh")) body.renderMesh = f->file();
  t.readNumber("scale", body.scale, kPositive);
  Vec3 rotation = Vec3::Zero();
  t.readVec3("rotation", rotation);
  body.rotationDeg = {rotation.x(), rotation.y(), rotation.z()};
  t.readVec3("position", body.position);
  t.readChoice("placement", body.placement, kPlacements);
  t.readChoice("mesher", body.mesher.mesher, kMeshers);
  t.exclusive("tets", "max_volume");  // a tet count search picks its own volume bound
  if (std::optional<Field> f = t.get("tets")) body.mesher.targetTets = std::size_t(f->integer(6, 2000000));
  t.readNumber("max_volume", body.mesher.maxVolume, kPositive);
  if (std::optional<Field> f = t.get("constraints")) body.constraints = readConstraints(*f);
  if (std::optional<Field> f = t.get("pin")) body.pin = readPins(*f);
  t.readNumber("pin_tolerance", body.pinTolerance, kNonNegative);
  t.readVec3("force", body.force);
  body.material = readMaterial(t.table("material"), body.kind);
  if (std::optional<Field> f = t.get("on")) body.on = f->name();
  body.contact = readBodyContact(t.table("contact"));
  return body;
}

Collider readCollider(const Table& t) {
  static constexpr Option<ColliderShape> kShapes[] = {
      {"plane", ColliderShape::Plane}, {"sphere", ColliderShape::Sphere}, {"box", ColliderShape::Box}};
  static const Keys kCommon = {"type", "static_friction", "dynamic_friction", "compliance"};
  static const Keys kPlane = {"normal", "point"}, kSphere = {"center", "radius"},
                    kBox = {"center", "half_extents", "rotation"};

  const Field type = t.require("type");
  const ColliderShape shape = type.choose(kShapes);
  const Keys& own = shape == ColliderShape::Plane ? kPlane : shape == ColliderShape::Sphere ? kSphere : kBox;
  Keys others;
  for (std::string_view key : concat(concat(kPlane, kSphere), kBox))
    if (!contains(own, key)) others.push_back(key);
  t.allowOnly(concat(kCommon, own), others, fmt::format("a {} collider", type.string()));

  Collider c;
  Vec3 center = Vec3::Zero();
  t.readVec3("center", center);
  switch (shape) {
    case ColliderShape::Plane: {
      Vec3 normal = Vec3::UnitY(), point = Vec3::Zero();
      t.readVec3("normal", normal);
      if (!(normal.norm() > 0.0f)) t.fail("normal", "must not be zero");
      t.readVec3("point", point);
      c = Collider::plane(normal, point);
      break;
    }
    case ColliderShape::Sphere:
      c = Collider::sphere(center, t.require("radius").number<float>(kPositive));
      break;
    case ColliderShape::Box: {
      const Vec3 halfExtents = t.require("half_extents").vec3(kPositive);
      Vec3 rotation = Vec3::Zero();
      t.readVec3("rotation", rotation);
      c = Collider::box(center, halfExtents, rotationFromDegrees(rotation));
      break;
    }
  }
  t.readNumber("static_friction", c.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", c.dynamicFriction, kNonNegative);
  t.readNumber("compliance", c.compliance, kNonNegative);
  validateAt(t, "collider", [&] { validateCollider(c); });
  return c;
}

ActionSpec readAction(const Table& t, const HandRigSettings& rig, std::string_view model,
                      const std::vector<BodySpec>& bodies) {
  static constexpr Option<ActionKind> kKinds[] = {{"poke", ActionKind::Poke}, {"grasp", ActionKind::Grasp}};
  static constexpr Option<Finger> kFingers[] = {{"thumb", Finger::Thumb},
                                                {"index", Finger::Index},
                                                {"middle", Finger::Middle},
                                                {"ring", Finger::Ring},
                                                {"little", Finger::Little}};
  static const Keys kCommon = {"type", "body", "finger", "start", "approach", "hold", "release", "depth", "offset"};
  static const Keys kGrasp = {"width", "lift"};
  static const Keys kPoke = {"profile"};
  static constexpr Option<PokeProfile> kProfiles[] = {{"minimum_jerk", PokeProfile::MinimumJerk},
                                                      {"linear", PokeProfile::Linear}};

  ActionSpec a;
  HandAction& h = a.action;
  h.kind = t.require("type").choose(kKinds);
  const bool poke = h.kind == ActionKind::Poke;
  t.allowOnly(concat(kCommon, poke ? kPoke : kGrasp), poke ? kGrasp : kPoke, poke ? "a poke" : "a grasp");

  if (std::optional<Field> f = t.get("body")) {
    a.body = f->string();
    std::vector<std::string_view> names;
    for (const BodySpec& b : bodies) names.push_back(b.name);
    if (!contains(names, a.body))
      f->fail(fmt::format("no body named '{}' (the bodies: {})", printable(a.body), fmt::join(names, ", ")));
  }
  if (std::optional<Field> f = t.get("finger")) {
    h.finger = f->choose(kFingers);
    if (!poke && h.finger == Finger::Thumb)
      f->fail("a grasp pairs the thumb with another finger; name that finger (index, middle, ring or little)");
    if (!rig.fingers[int(h.finger)])
      f->fail(fmt::format("the {} hand has no {} fingertip (model = \"pro\" has all five)", model, f->string()));
  }
  t.readNumber("start", h.start, kNonNegative);
  t.readNumber("approach", h.approach, kPositive);
  t.readNumber("hold", h.hold, kNonNegative);
  t.readNumber("release", h.release, kPositive);
  t.readNumber("depth", h.depth, kNonNegative);
  t.readNumber("width", h.width, kNonNegative);
  t.readNumber("lift", h.lift, kNonNegative);
  t.readVec3("offset", a.offset);
  t.readChoice("profile", h.profile, kProfiles);
  return a;
}

HandSpec readHand(const Table& t, const std::vector<BodySpec>& bodies) {
  static constexpr Option<std::string_view> kModels[] = {{"g1", "g1"}, {"pro", "pro"}};
  static constexpr Option<FingertipContactMode> kContacts[] = {{"particles", FingertipContactMode::Particles},
                                                               {"triangles", FingertipContactMode::Triangles}};
  static constexpr Option<std::optional<GraspMode>> kGrasps[] = {
      {"local", GraspMode::Local}, {"paper", GraspMode::Paper}, {"off", std::nullopt}};
  t.allowOnly({"enabled", "model", "contact", "fingertip_radius", "compliance", "static_friction", "dynamic_friction",
               "grasp", "release_opening", "closing_speed", "hold_reach", "hold_compliance", "script", "action"});

  HandSpec hand;
  t.readBool("enabled", hand.enabled);
  std::string_view model = "g1";
  t.readChoice("model", model, kModels);
  hand.rig = model == "pro" ? HandRigSettings::pro() : HandRigSettings::g1();
  hand.rig.contact = FingertipContactMode::Triangles;  // the scene defaults, unlike HandRigSettings'
  hand.rig.friction = kSkin;
  t.readChoice("contact", hand.rig.contact, kContacts);
  t.readNumber("fingertip_radius", hand.rig.geometry.fingertipRadius, kPositive);
  t.readNumber("compliance", hand.rig.compliance, kNonNegative);
  t.readNumber("static_friction", hand.rig.friction.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", hand.rig.friction.dynamicFriction, kNonNegative);

  std::optional<GraspMode> grasp = hand.grasp.mode;
  t.readChoice("grasp", grasp, kGrasps);
  hand.grasp.enabled = grasp.has_value();
  hand.grasp.mode = grasp.value_or(hand.grasp.mode);
  t.readNumber("release_opening", hand.grasp.releaseOpening, kNonNegative);
  t.readNumber("closing_speed", hand.grasp.closingSpeed, kNonNegative);
  t.readNumber("hold_reach", hand.grasp.holdReach, kNonNegative);
  t.readNumber("hold_compliance", hand.grasp.holdCompliance, kNonNegative);
  validateAt(t, "grasp", [&] { validateGraspSettings(hand.grasp); });

  if (std::optional<Field> f = t.get("script")) hand.script = f->file();
  for (const Table& action : t.tables("action")) hand.actions.push_back(readAction(action, hand.rig, model, bodies));
  if (!hand.script.empty() && !hand.actions.empty())
    t.fail("script", "a script replaces the [[hand.action]] list; give one or the other");
  return hand;
}

OutputSpec readOutput(const Table& t) {
  t.allowOnly({"mesh_every", "plots"});
  OutputSpec out;
  t.readNumber("mesh_every", out.meshEvery, kNonNegative);
  t.readBool("plots", out.plots);
  return out;
}

bool hasBody(const std::vector<BodySpec>& bodies, std::string_view name) {
  return std::any_of(bodies.begin(), bodies.end(), [&](const BodySpec& b) { return b.name == name; });
}

SceneSpec readScene(const Table& root, std::string_view sourceName) {
  root.allowOnly({"format", "name", "description", "settle", "seconds", "wind", "ground", "solver", "body", "collider",
                  "no_contact", "hand", "haptics", "output"});
  if (std::optional<Field> f = root.get("format"); f && f->integer() != 1)
    f->fail(fmt::format("this vrdeform reads format 1, got {}", f->integer()));

  SceneSpec scene;
  scene.name = fs::path(sourceName).stem().string();
  if (std::optional<Field> f = root.get("name")) scene.name = f->name();
  root.readString("description", scene.description);
  // Until the bodies are at rest (at most kSettleToRestMost s) unless the file says how long.
  scene.settleToRest = !root.has("settle");
  scene.settle = scene.settleToRest ? SceneSpec::kSettleToRestMost : scene.settle;
  root.readNumber("settle", scene.settle, kNonNegative);
  root.readNumber("seconds", scene.seconds, kPositive);
  root.readVec3("wind", scene.wind);
  scene.solver.substeps = kSceneSubsteps;
  scene.solver.measureResiduals = true;  // runs and the viewer show how converged each step is
  readSolverTable(root.table("solver"), scene.solver);

  const std::vector<Table> bodies = root.tables("body");
  if (!root.has("body")) root.fail("body", "missing (a scene needs at least one [[body]])");
  if (bodies.empty()) root.fail("body", "is empty (a scene needs at least one [[body]])");
  for (const Table& t : bodies) {
    BodySpec body = readBody(t, scene.bodies.size() + 1);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
      if (scene.bodies[i].name == body.name)
        t.fail("name", fmt::format("'{}' is also the name of body[{}]", printable(body.name), i + 1));
    if (!body.on.empty() && !hasBody(scene.bodies, body.on))
      t.fail("on", fmt::format("no body '{}' before this one", printable(body.on)));
    scene.bodies.push_back(std::move(body));
  }
  for (const Table& t : root.tables("no_contact")) {
    t.allowOnly({"bodies"});
    const std::vector<Field> names = t.require("bodies").elements("an array of two body names");
    if (names.size() != 2) t.fail("bodies", fmt::format("needs two body names, got {}", names.size()));
    std::array<std::string, 2> pair{names[0].name(), names[1].name()};
    for (const std::string& name : pair)
      if (!hasBody(scene.bodies, name)) t.fail("bodies", fmt::format("no body '{}'", printable(name)));
    if (pair[0] == pair[1]) t.fail("bodies", "names one body twice (its self-contact is [body.contact] self)");
    scene.noContact.push_back(std::move(pair));
  }
  for (const Table& t : root.tables("collider")) scene.colliders.push_back(readCollider(t));
  bool ground = true;  // a scene of a mesh alone stands on something
  root.readBool("ground", ground);
  if (ground && scene.colliders.empty()) scene.colliders.push_back(Collider::plane(Vec3::UnitY()));
  scene.hand = readHand(root.table("hand"), scene.bodies);
  readHapticsTable(root.table("haptics"), scene.haptics);
  scene.output = readOutput(root.table("output"));
  return scene;
}

}  // namespace

void readSolverTable(const Table& t, SolverSettings& s) {
  t.allowOnly({"rate", "dt", "substeps", "iterations", "gravity", "linear_damping", "simd", "threads",
               "fuse_strain_volume", "measure_residuals", "tolerance", "warm_start"});
  t.exclusive("rate", "dt");
  if (std::optional<Field> f = t.get("rate")) s.timeStep = 1.0 / double(f->integer(1, 100000));
  t.readNumber("dt", s.timeStep, kPositive);
  t.readInt("substeps", s.substeps, 1, 1000);
  t.readInt("iterations", s.iterations, 1, 1000);
  t.readVec3("gravity", s.gravity);
  t.readNumber("linear_damping", s.linearDamping, kNonNegative);
  if (t.has("simd")) {
    bool simd = true;
    t.readBool("simd", simd);
    s.simd = simd ? SimdLevel::Best : SimdLevel::Off;
  }
  if (std::optional<Field> f = t.get("threads")) {
    if (f->isString() && f->string() != "auto")
      f->fail(fmt::format("expected an integer or \"auto\", got '{}'", printable(f->string())));
    s.threads = f->isString() ? SolverSettings::kAutoThreads : int(f->integer(1, 256));
  }
  t.readBool("fuse_strain_volume", s.fuseStrainVolume);
  t.readBool("measure_residuals", s.measureResiduals);
  t.readNumber("tolerance", s.tolerance, kNonNegative);
  t.readBool("warm_start", s.warmStart);
  validateAt(t, "solver", [&] { validateSolverSettings(s); });
}

void readHapticsTable(const Table& t, HapticsSpec& h) {
  t.allowOnly({"calibrate", "alpha", "beta_contact", "beta_volume", "beta_strain", "epsilon", "tau_contact",
               "tau_finger_contact", "tau_volume", "tau_strain", "max_change_per_ms", "baseline_contact_force",
               "baseline_stiffness"});
  HapticSignalSettings& s = h.settings.signal;
  t.readBool("calibrate", h.calibrate);
  t.readNumber("alpha", s.alphaT, Range{0, 1, true, false});
  t.readNumber("beta_contact", s.betaContact, kUnit);
  // beta_v + beta_s = 1 (eq. 42), so one of them gives the other.
  t.readNumber("beta_volume", s.betaVolume, kUnit);
  t.readNumber("beta_strain", s.betaStrain, kUnit);
  if (t.has("beta_volume") && !t.has("beta_strain")) s.betaStrain = 1.0f - s.betaVolume;
  if (t.has("beta_strain") && !t.has("beta_volume")) s.betaVolume = 1.0f - s.betaStrain;
  if (std::abs(s.betaVolume + s.betaStrain - 1.0f) > 1e-4f)
    t.fail("beta_strain", fmt::format("beta_volume + beta_strain must be 1, got {}", s.betaVolume + s.betaStrain));
  t.readNumber("epsilon", s.epsilon, kNonNegative);
  t.readNumber("tau_contact", s.tauContact, kPositive);
  t.readNumber("tau_finger_contact", s.tauFingerContact, kPositive);
  t.readNumber("tau_volume", s.tauVolume, kPositive);
  t.readNumber("tau_strain", s.tauStrain, kPositive);
  if (std::optional<Field> f = t.get("max_change_per_ms")) {
    if (f->isString() && f->string() != "inf")
      f->fail(fmt::format("expected a number or \"inf\", got '{}'", printable(f->string())));
    const bool unlimited = f->isString() || f->real() == kInf;
    h.settings.maxChangePerMs = unlimited ? std::numeric_limits<float>::infinity() : f->number<float>(kPositive);
  }
  t.readNumber("baseline_contact_force", h.settings.baseline.contactForce, kUnit);
  t.readNumber("baseline_stiffness", h.settings.baseline.stiffness, kNonNegative);
  validateAt(t, "haptics", [&] { validateHapticSettings(h.settings); });
}

SceneSpec parseScene(std::string_view text, std::string_view sourceName, const fs::path& baseDir) {
  const Context ctx{std::string(sourceName), baseDir};
  const toml::table root = parseToml(text, ctx.source);
  SceneSpec scene = readScene(Table(ctx, root, "", 1), sourceName);
  scene.source = sourceName;
  return scene;
}

SceneSpec loadScene(const fs::path& path) {
  const std::string text = readText(path);
  std::error_code error;
  fs::path absolute = fs::absolute(path, error);
  if (error) absolute = path;
  absolute = absolute.lexically_normal();
  SceneSpec scene = parseScene(text, path.string(), absolute.parent_path());
  scene.source = absolute.string();
  return scene;
}

SceneSpec sceneOfMesh(const fs::path& mesh) {
  const toml::table root{{"body", toml::array{toml::table{{"mesh", mesh.string()}}}}};
  std::error_code error;
  const Context ctx{mesh.string(), fs::current_path(error)};
  SceneSpec scene = readScene(Table(ctx, root, "", 1), mesh.string());
  scene.source = scene.bodies.front().mesh;
  return scene;
}

}  // namespace vrd
