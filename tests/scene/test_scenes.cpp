// The built-in scenes (scenes/*.toml: the paper's six) and running them (scene/scene_run.h).

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_support.h"
#include "vrdeform/scene/scene_file.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {
namespace {

std::vector<std::string> names() {
  std::vector<std::string> n;
  for (const SceneEntry& e : builtinScenes()) n.push_back(e.name);
  return n;
}

// The paper's six, and three of bodies touching each other (docs/contact.md).
TEST(Scenes, ThePapersSixAndTheContactScenesAreBuiltIn) {
  EXPECT_EQ(names(), (std::vector<std::string>{"balloon", "bear", "drape", "flag", "furball", "jelly", "jelly_stack",
                                               "liver", "liver_pad"}));
}

// The paper's tet counts (Table 1): the meshers land within 15% of them. The liver is the CT
// surface's own tets instead (1,177, not 770: scenes/liver.toml says why).
TEST(Scenes, TetCountsAreNearThePapers) {
  const std::map<std::string, std::size_t> paper{{"furball", 1280}, {"balloon", 1713}, {"jelly", 1530}, {"bear", 1041}};
  for (const auto& [name, tets] : paper) {
    SceneSpec spec = loadSceneByName(name);
    spec.settle = 0.0;
    spec.haptics.calibrate = false;
    const BuiltScene scene = buildScene(spec);
    const double n = double(scene.bodies.front().model->tets.size());
    EXPECT_NEAR(n / double(tets), 1.0, 0.15) << name << ": " << n << " tets";
  }
}

// The liver's drawn surface (liver.obj, 2,557 vertices) is where its tets are, so a fingertip meets
// the body where the eye sees it: its tets keep liver_coarse.obj's triangles as their boundary, and
// the two surfaces are remeshings of one CT level set (facet distances 0.7 and 3 mm), so no drawn
// vertex lies more than about 4 mm outside the body (a 770-tet lattice left 18 mm).
TEST(Scenes, TheLiversDrawnSurfaceLiesOnItsTets) {
  SceneSpec spec = loadSceneByName("liver");
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  const BuiltScene scene = buildScene(spec);
  ASSERT_TRUE(scene.bodies.front().embedding);
  const Embedding& drawn = *scene.bodies.front().embedding;
  EXPECT_EQ(drawn.vertexCount(), 2557u);
  testing::record("max_outside_distance_m", drawn.maxOutsideDistance());
  EXPECT_LT(drawn.maxOutsideDistance(), 0.005);
}

class EveryScene : public ::testing::TestWithParam<std::string> {};

// Two simulated seconds after settling, with the scripted poke under way: finite, volume kept to
// within the paper's 1%, forces in [0, 1] and the poking finger feeling the body.
TEST_P(EveryScene, RunsTwoSecondsWithoutNaNKeepingItsVolume) {
  BuiltScene scene = buildScene(loadSceneByName(GetParam()));
  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(2.0 / scene.spec.solver.timeStep));
  float lowest = 1.0f, highest = 0.0f;
  settings.afterStep = [&](const RunStep& s) {
    for (const FingerHaptics& f : s.session->haptics().fingers) {
      lowest = std::min(lowest, f.force);
      highest = std::max(highest, f.force);
    }
    return true;
  };
  const RunSummary r = runScene(scene, settings);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.steps, settings.steps);
  EXPECT_EQ(r.nanEvents, 0u);
  for (Index i = 0; i < scene.world->particles().x.size(); ++i)
    ASSERT_TRUE(isFinite(scene.world->particles().x[i].pos)) << "particle " << i;
  EXPECT_LT(r.volumeLossMax, 0.01);
  EXPECT_GE(lowest, 0.0f);
  EXPECT_LE(highest, 1.0f);
  EXPECT_GT(r.forceMax[int(Finger::Index)], 0.1f) << "the poke should be felt within 2 s";
  testing::record("volume_loss_max", r.volumeLossMax);
  testing::record("index_force_max", r.forceMax[int(Finger::Index)]);
}

class EveryBody : public ::testing::TestWithParam<std::string> {};

// The whole scripted interaction: the pinch of each tet body becomes a grasp, and the volume stays
// within 1% through the poke, the grasp, the lift and the drop.
TEST_P(EveryBody, WholeRunGraspsAndKeepsItsVolume) {
  BuiltScene scene = buildScene(loadSceneByName(GetParam()));
  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(scene.spec.seconds / scene.spec.solver.timeStep));
  std::uint64_t grasped = 0;
  settings.afterStep = [&](const RunStep& s) {
    grasped += s.session->grasp().active();
    return true;
  };
  const RunSummary r = runScene(scene, settings);
  EXPECT_EQ(r.nanEvents, 0u);
  EXPECT_LT(r.volumeLossMax, 0.01);
  EXPECT_GT(grasped, 30u) << "the pinch should hold the body for at least half a second";
  ASSERT_EQ(r.grasps.size(), 1u);  // the summary's account of the pinch: the steps the grasp held
  EXPECT_NEAR(r.grasps[0].heldSeconds, double(grasped) * r.dt, 1e-9);
  EXPECT_LT(r.coldSubstepShare, 0.02) << "the warm start keeps falling back: the scene needs more substeps";
  testing::record("cold_substep_share", r.coldSubstepShare);
  EXPECT_GT(r.forceMax[int(Finger::Thumb)], 0.1f);
  // Table 3's two states: the hand touches during the poke and the grasp, and is idle between.
  EXPECT_GE(r.latency.frames(Phase::Contact), grasped);
  EXPECT_GT(r.latency.frames(Phase::Idle), 60u);
  // The scripted poke's signal: a force that starts and ends at 0 has roughness >= 1 (0.99: the
  // smoothed value may still be decaying 0.3 s after the release).
  ASSERT_EQ(r.pokes.size(), 1u);
  const PokeSignal& poke = r.pokes[0];
  EXPECT_EQ(poke.finger, Finger::Index);
  for (const SignalQuality* q : {&poke.newtons, &poke.force}) {
    EXPECT_GE(q->roughness, 0.99);
    EXPECT_GT(q->loadingSpearman, 0.0);
  }
  EXPECT_GT(poke.newtons.peak, 0.0);
  EXPECT_LE(poke.newtons.peak, r.newtonsMax[int(Finger::Index)]);
  EXPECT_LE(poke.force.peak, r.forceMax[int(Finger::Index)]);
  testing::record("volume_loss_max", r.volumeLossMax);
  testing::record("grasped_steps", double(grasped));
  testing::record("poke_roughness_newtons", poke.newtons.roughness);
  testing::record("poke_roughness_normalised", poke.force.roughness);
}

// Each scene's scripted poke: one clean rise and fall, a force that only rises while the finger
// presses, and a steady hold, in newtons and normalised. What made them rough: round bodies rolled
// away under a frictionless fingertip (the liver: roughness 3.03 in newtons, hold noise 13%), the
// bear's thin parts swung under it, and a poke that stopped dead set the jelly and the balloon
// ringing under the held finger (hold noise 2-2.6%), which a minimum-jerk approach does not.
class EveryPoke : public ::testing::TestWithParam<const char*> {};

// Issue 30's bars, in newtons and normalised: one clean rise and fall, a force that only rises while
// the finger presses, a steady hold.
void expectCleanSignal(const PokeSignal& poke) {
  for (const SignalQuality* q : {&poke.newtons, &poke.force}) {
    EXPECT_LE(q->roughness, 1.10);
    EXPECT_GE(q->loadingSpearman, 0.99);
    EXPECT_LT(q->holdNoise, 0.01);
  }
}

void expectSmoothPoke(const char* name) {
  BuiltScene scene = buildScene(loadSceneByName(name));
  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(4.5 / scene.spec.solver.timeStep));  // the poke and 0.3 s after
  const RunSummary r = runScene(scene, settings);
  ASSERT_EQ(r.pokes.size(), 1u);
  expectCleanSignal(r.pokes[0]);
  EXPECT_LE(r.pokes[0].newtons.lagSteps, 1);  // steps behind the depth
  EXPECT_LE(r.pokes[0].force.lagSteps, 1);
  testing::record("roughness_newtons", r.pokes[0].newtons.roughness);
  testing::record("spearman_newtons", r.pokes[0].newtons.loadingSpearman);
  testing::record("hold_noise_newtons", r.pokes[0].newtons.holdNoise);
}

TEST_P(EveryPoke, IsSmoothMonotoneAndSteady) { expectSmoothPoke(GetParam()); }

// The drape's poke presses the cloth into the jelly. At 8 x 5 the light cloth squeezed under the
// fingertip made the warm start fall back cold there (roughness 1.8 in newtons, loading Spearman
// 0.93). Its newtons are not compared with a converged run: where the cloth's folds settle depends on
// the solve, so the poke meets a different drape (held, 0.59-0.61 N from 16 x 4 to 24 x 10).
TEST(Scenes, TheDrapesPokeThroughTheClothIsSmoothMonotoneAndSteady) { expectSmoothPoke("drape"); }

// The newtons are right: each poke's peak, held for a second, within 5% of the same scene solved
// with twice the substeps and four times the iterations (the scenes start each substep warm,
// SolverSettings::warmStart; cold, the liver read 4.9 N against a converged 1.9 N, the bear 0.08 N
// against 3.3 N).
TEST_P(EveryPoke, NewtonsMatchAConvergedRun) {
#ifdef __SANITIZE_ADDRESS__
  GTEST_SKIP() << "eight times the scene's arithmetic: the release build checks it";
#endif
  const auto peak = [](const SceneSpec& spec) {
    BuiltScene scene = buildScene(spec);
    RunSettings settings;
    settings.steps = std::uint64_t(std::lround(4.5 / spec.solver.timeStep));
    const RunSummary r = runScene(scene, settings);
    return r.pokes.empty() ? 0.0 : double(r.pokes[0].newtons.peak);
  };
  const SceneSpec spec = loadSceneByName(GetParam());
  SceneSpec converged = spec;
  converged.solver.substeps *= 2;
  converged.solver.iterations *= 4;
  const double newtons = peak(spec), reference = peak(converged);
  EXPECT_NEAR(newtons, reference, 0.05 * reference);
  testing::record("newtons", newtons);
  testing::record("converged_newtons", reference);
}

INSTANTIATE_TEST_SUITE_P(Builtin, EveryPoke, ::testing::Values("furball", "liver", "balloon", "jelly", "bear"));
INSTANTIATE_TEST_SUITE_P(Contact, EveryPoke, ::testing::Values("jelly_stack", "liver_pad"));

// A substep that starts cold while a fingertip touches a body rebuilds its contacts' multipliers from
// zero: a dip in the force. The drape at its former 8 x 5 had four while the finger pressed the cloth
// into the jelly, and its poke read rough (1.8 in newtons); the run's summary counts them.
TEST(SceneRun, CountsTheColdSubstepsWhileAFingertipTouches) {
  SceneSpec spec = loadSceneByName("drape");
  spec.solver.substeps = 8;
  spec.solver.iterations = 5;
  BuiltScene scene = buildScene(spec);
  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(3.5 / spec.solver.timeStep));  // the poke and 0.3 s after
  std::uint64_t touching = 0, all = 0;
  settings.afterStep = [&](const RunStep& s) {
    const int cold = s.session->world().lastStep().coldSubsteps;
    all += std::uint64_t(cold);
    if (s.session->inContact()) touching += std::uint64_t(cold);
    return true;
  };
  const RunSummary r = runScene(scene, settings);
  EXPECT_GT(r.coldSubstepsTouching, 0u);
  EXPECT_EQ(r.coldSubstepsTouching, touching);
  EXPECT_NEAR(r.coldSubstepShare, double(all) / double(r.steps * std::uint64_t(spec.solver.substeps)), 1e-12);
  ASSERT_EQ(r.pokes.size(), 1u);
  EXPECT_GT(r.pokes[0].newtons.roughness, 1.10);
  testing::record("cold_substeps_touching", double(r.coldSubstepsTouching));
}

// A poke on a scene a user writes, the mesh, its scale and the poke and nothing else: the liver's
// mesh in millimetres under soft tissue, pressed 1.5 cm over a second. Frictionless (the paper's
// fingertips) it rolled under the finger: roughness 3.04, loading Spearman -0.65 and hold noise 78%
// in newtons; with the scene files' default skin friction it meets the built-in scenes' bars.
TEST(Scenes, AUserScenesPokeIsSmoothMonotoneAndSteady) {
  const SceneSpec spec = parseScene(R"([[body]]
mesh = "liver_coarse.obj"
scale = 0.001
[[hand.action]]
type = "poke"
start = 0.5
approach = 1.0
hold = 1.0
release = 0.5
depth = 0.015
)",
                                    "user.toml", VRDEFORM_SHARED_DIR "/data/meshes");
  BuiltScene scene = buildScene(spec);
  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(3.3 / spec.solver.timeStep));  // the poke and 0.3 s after
  const RunSummary r = runScene(scene, settings);
  ASSERT_EQ(r.pokes.size(), 1u);
  expectCleanSignal(r.pokes[0]);
  testing::record("roughness_newtons", r.pokes[0].newtons.roughness);
  testing::record("hold_noise_newtons", r.pokes[0].newtons.holdNoise);
}

// The liver's poke, held for a second, read in newtons: cold (the scene as it is, 8 x 5) off by more
// than half from a converged run of the same scene (2 x the substeps, 4 x the iterations; whether
// above or below depends on the mesh); with a warm start
// (SolverSettings::warmStart), which makes the held body a fixed point of any number of
// iterations, within 5% of it.
TEST(Scenes, AWarmStartedPokeReadsTheConvergedNewtons) {
#ifdef __SANITIZE_ADDRESS__
  GTEST_SKIP() << "eight times the scene's arithmetic: the release build checks it";
#endif
  const auto peak = [](bool warm, int substeps, int iterations) {
    SceneSpec spec = loadSceneByName("liver");
    spec.solver.warmStart = warm;
    spec.solver.substeps *= substeps;
    spec.solver.iterations *= iterations;
    BuiltScene scene = buildScene(spec);
    RunSettings settings;
    settings.steps = std::uint64_t(std::lround(4.5 / spec.solver.timeStep));
    const RunSummary r = runScene(scene, settings);
    return r.pokes.empty() ? 0.0 : double(r.pokes[0].newtons.peak);
  };
  const double converged = peak(true, 2, 4), warm = peak(true, 1, 1), cold = peak(false, 1, 1);
  EXPECT_NEAR(warm, converged, 0.05 * converged);
  EXPECT_GT(std::max(cold / converged, converged / cold), 1.5);
  testing::record("warm_newtons", warm);
  testing::record("cold_newtons", cold);
  testing::record("converged_newtons", converged);
}

double totalMass(const BodyModel& m) {
  double kg = 0.0;
  for (float w : m.invMass) kg += 1.0 / double(w);
  return kg;
}

// A body without a material weighs what its volume of water weighs (it used to weigh 1 kg per
// particle: 291 kg for the liver).
TEST(Scenes, ABodyWithoutAMaterialWeighsItsVolumeOfWater) {
  SceneSpec spec = loadSceneByName("liver");
  spec.bodies[0].material = Material{};
  spec.hand.enabled = false;
  spec.settle = 0.0;
  const BuiltScene scene = buildScene(spec);
  const BodyModel& m = *scene.bodies[0].model;
  EXPECT_NEAR(totalMass(m), 1000.0 * m.restVolume, 1e-5 * 1000.0 * m.restVolume);
  testing::record("kg", totalMass(m));
}

// The flag weighs a light fabric's 0.2 kg/m^2 (0.3125 kg, not the paper's 841 kg), and with the
// paper's compliances divided by its particle mass and the wind as an acceleration it moves as the
// paper's flag does while its forces scale with the mass.
TEST(Scenes, TheFlagWeighsAFlagsWeightAndMovesAsThePapersFlagDoes) {
  const SceneSpec physical = loadSceneByName("flag");
  SceneSpec paper = physical;
  Material& m = paper.bodies[0].material;
  m.particleMass = 1.0f;
  m.distance.compliance = 1e-6f;
  m.bending.compliance = 1.0f;
  BuiltScene a = buildScene(physical), b = buildScene(paper);
  const double kg = totalMass(*a.bodies[0].model);
  EXPECT_NEAR(kg, 0.2 * 1.25 * 1.25, 1e-3);
  EXPECT_NEAR(totalMass(*b.bodies[0].model), 841.0, 1e-3);

  RunSettings settings;
  settings.steps = std::uint64_t(std::lround(2.0 / physical.solver.timeStep));  // the poke
  const RunSummary ra = runScene(a, settings), rb = runScene(b, settings);
  double distance = 0.0;
  const auto& pa = a.world->particles().x;
  const auto& pb = b.world->particles().x;
  for (std::size_t i = 0; i < pa.size(); ++i) distance += double((pa[i].pos - pb[i].pos).norm());
  EXPECT_LT(distance / double(pa.size()), 1e-3);  // m, on a 1.25 m flag
  const int index = int(Finger::Index);
  ASSERT_GT(rb.newtonsMax[index], 0.0f);
  EXPECT_NEAR(ra.newtonsMax[index] / rb.newtonsMax[index], kg / 841.0, 0.1 * kg / 841.0);
  testing::record("poke_newtons", ra.newtonsMax[index]);
  testing::record("paper_poke_newtons", rb.newtonsMax[index]);
}

INSTANTIATE_TEST_SUITE_P(Builtin, EveryBody, ::testing::Values("balloon", "bear", "furball", "jelly", "liver"));
INSTANTIATE_TEST_SUITE_P(Contact, EveryBody, ::testing::Values("jelly_stack", "liver_pad"));

INSTANTIATE_TEST_SUITE_P(Builtin, EveryScene,
                         ::testing::Values("balloon", "bear", "flag", "furball", "jelly", "liver"));
// The scenes of bodies touching bodies (docs/contact.md): labelled long, as their detection makes
// them slow under the sanitizers and the emulator.
INSTANTIATE_TEST_SUITE_P(Contact, EveryScene, ::testing::Values("drape", "jelly_stack", "liver_pad"));

TEST(SceneRun, WritesEveryOutputAndASummaryWithTheDocumentedKeys) {
  const testing::TempDir dir;
  SceneSpec spec = loadSceneByName("liver");
  spec.output.meshEvery = 0.5;
  BuiltScene scene = buildScene(spec);
  RunSettings settings;
  settings.steps = 150;  // 2.5 s: into the poke's hold
  settings.outDir = dir.path() / "out";
  const RunSummary r = runScene(scene, settings);
  for (const char* f :
       {"summary.json", "forces.csv", "stage_times.csv", "latency.csv", "force_time.svg", "force_indentation.svg",
        "meshes/liver.pvd", "meshes/liver_00000.vtu", "meshes/liver_00004.vtu"})
    EXPECT_TRUE(std::filesystem::is_regular_file(settings.outDir / f)) << f;

  std::ifstream in(settings.outDir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const char* key : {"scene", "steps", "dt", "tets", "particles", "constraints", "volume_loss_max",
                          "volume_loss_final", "body_contacts_max", "penetration_max_m", "force_max", "stage_ms",
                          "nan_events", "ok", "pokes", "cold_substep_share", "cold_substeps_touching"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["pokes"].empty()) << "the poke was cut off at 2.5 s: no figures for half a press";
  EXPECT_GT(j["residuals"]["strain_volume"]["max"].get<double>(), 0.0);  // measured, and not converged at 8 x 5
  EXPECT_EQ(j["iterations_mean"].get<double>(), 40.0);
  EXPECT_EQ(j["scene"], "liver");
  EXPECT_EQ(j["steps"], 150);
  EXPECT_EQ(j["ok"], true);

  EXPECT_EQ(j["tets"], r.tets);
  EXPECT_EQ(j["constraints"]["volume"], r.tets);
  EXPECT_EQ(j["constraints"]["shape_matching"], 1);
  EXPECT_DOUBLE_EQ(j["force_max"]["index"].get<double>(), double(r.forceMax[int(Finger::Index)]));
  for (const char* stat : {"mean", "p50", "p95", "p99"}) EXPECT_GT(j["stage_ms"]["total"][stat].get<double>(), 0.0);
  EXPECT_LE(j["stage_ms"]["total"]["p50"].get<double>(), j["stage_ms"]["total"]["p99"].get<double>());

  // The force trace: a header and a row per step, time increasing.
  std::ifstream csv(settings.outDir / "forces.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_TRUE(line.starts_with("step,time_s,wall_ms,paper,paper_raw,grasp,thumb,thumb_N,")) << line;
  std::size_t rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    EXPECT_TRUE(line.starts_with(std::to_string(rows) + ",")) << "row " << rows << ": " << line;
  }
  EXPECT_EQ(rows, 150u);

  // [output] plots = false, mesh_every = 0: the per-step files and the summary only.
  spec.output.meshEvery = 0.0;
  spec.output.plots = false;
  BuiltScene bare = buildScene(spec);
  settings.outDir = dir.path() / "bare";
  settings.steps = 10;
  runScene(bare, settings);
  EXPECT_TRUE(std::filesystem::is_regular_file(settings.outDir / "forces.csv"));
  for (const char* f : {"force_time.svg", "force_indentation.svg", "meshes"})
    EXPECT_FALSE(std::filesystem::exists(settings.outDir / f)) << f;
}

TEST(SceneRun, WritesClothAndRenderMeshesToo) {
  const testing::TempDir dir;
  for (const char* name : {"flag", "bear"}) {
    SceneSpec spec = loadSceneByName(name);
    spec.settle = 0.0;
    spec.haptics.calibrate = false;
    spec.hand.enabled = std::string(name) == "bear";  // a scene without a hand writes its meshes too
    BuiltScene scene = buildScene(spec);
    RunSettings settings;
    settings.steps = 12;  // mesh frames every 0.1 s: 2
    settings.outDir = dir.path() / name;
    const RunSummary r = runScene(scene, settings);
    EXPECT_NE(std::find(r.files.begin(), r.files.end(), std::filesystem::path("meshes") / (std::string(name) + ".pvd")),
              r.files.end());
  }
  const auto points = [](const std::filesystem::path& vtu) {
    std::ifstream in(vtu);
    std::string head(400, '\0');
    in.read(head.data(), 400);
    const std::size_t at = head.find("NumberOfPoints=\"");
    return at == std::string::npos ? -1 : std::stol(head.substr(at + 16));
  };
  EXPECT_EQ(points(dir.path() / "flag" / "meshes" / "flag_00001.vtu"), 841);           // the cloth's particles
  EXPECT_EQ(points(dir.path() / "bear" / "meshes" / "bear_render_00001.vtu"), 13826);  // bear.obj, carried by the tets
}

TEST(SceneRun, AFailedRunStillLeavesASummarySayingSo) {
  const testing::TempDir dir;
  SceneSpec spec = loadSceneByName("jelly");
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  BuiltScene scene = buildScene(spec);
  RunSettings settings;
  settings.steps = 10;
  settings.outDir = dir.path() / "out";
  settings.afterStep = [](const RunStep& s) -> bool {
    if (s.step == 4) throw Error("disk full");
    return true;
  };
  EXPECT_NE(testing::errorOf([&] { runScene(scene, settings); }).find("disk full"), std::string::npos);
  std::ifstream in(settings.outDir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["ok"], false);
  EXPECT_EQ(j["steps"], 5);
  EXPECT_EQ(j["error"], "disk full");
}

// A body that goes non-finite while settling is frozen there, and the run's summary says so (it
// counted only the run's own steps before).
TEST(SceneRun, ANaNWhileSettlingIsInTheSummary) {
  SceneSpec spec = loadSceneByName("jelly");
  spec.settle = 0.1;
  spec.haptics.calibrate = false;
  spec.hand.enabled = false;
  spec.bodies.front().force = Vec3(0.0f, 1e37f, 0.0f);  // N on every particle: overflows in a step
  BuiltScene scene = buildScene(spec);
  ASSERT_EQ(scene.settleEvents.size(), 1u);
  RunSettings settings;
  settings.steps = 3;
  const RunSummary summary = runScene(scene, settings);
  EXPECT_EQ(summary.nanEvents, 1u);
  ASSERT_EQ(summary.events.size(), 1u);
  EXPECT_EQ(summary.events.front().rfind("settling, step 0: ", 0), 0u) << summary.events.front();
  EXPECT_NE(summaryJson(summary).find("\"nan_events\": 1"), std::string::npos);
}

// A mesh in millimetres taken as metres: the build says so and what scale would fix it.
TEST(SceneBuilder, AGiantBodyGetsAWarningAboutUnits) {
  SceneSpec spec = parseScene("[[body]]\nmesh = \"liver_coarse.obj\"\ntets = 200\n[hand]\nenabled = false\n", "mm.toml",
                              VRDEFORM_SHARED_DIR "/data/meshes");
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  std::vector<std::string> log;
  buildScene(spec, [&](std::string_view line) { log.emplace_back(line); });
  const auto warning =
      std::find_if(log.begin(), log.end(), [](const std::string& l) { return l.starts_with("warning"); });
  ASSERT_NE(warning, log.end());
  EXPECT_NE(warning->find("is 19"), std::string::npos) << *warning;  // m across: the liver's ~19 cm in mm
  EXPECT_NE(warning->find("scale = 0.001 makes it 0.19"), std::string::npos) << *warning;
}

// A scene file without `settle` settles until every particle is slower than 5 mm/s; with it, as
// long as it says.
TEST(SceneBuilder, ASceneFileWithoutSettleSettlesToRest) {
  const std::string body = "[[body]]\nmesh = \"sphere_coarse.obj\"\nscale = 0.03\n[hand]\nenabled = false\n";
  SceneSpec spec = parseScene(body, "rest.toml", VRDEFORM_SHARED_DIR "/data/meshes");
  std::vector<std::string> log;
  BuiltScene scene = buildScene(spec, [&](std::string_view line) { log.emplace_back(line); });
  EXPECT_GE(scene.settleSeconds, 0.5);
  EXPECT_LT(scene.settleSeconds, SceneSpec::kSettleToRestMost);
  for (const Vec3& v : scene.world->particles().v) EXPECT_LT(v.norm(), SceneSpec::kRestSpeed);
  EXPECT_TRUE(std::any_of(log.begin(), log.end(), [](const std::string& l) { return l.ends_with(": at rest"); }));
  spec = parseScene("settle = 0.3\n" + body, "fixed.toml", VRDEFORM_SHARED_DIR "/data/meshes");
  EXPECT_DOUBLE_EQ(buildScene(spec).settleSeconds, std::round(0.3 * 60) / 60);
}

// The observer's stop ends each phase of a build where it is, saying where: the caller's Ctrl-C.
TEST(SceneBuilder, StopsWhileMeshingSettlingOrCalibrating) {
  const auto stoppedAt = [](SceneSpec spec, int polls, std::vector<std::pair<double, double>>* settled = nullptr) {
    SceneBuildObserver o;
    o.stop = [polls, n = 0]() mutable { return ++n > polls; };
    if (settled) o.settling = [settled](double done, double total) { settled->emplace_back(done, total); };
    try {
      buildScene(spec, o);
    } catch (const Stopped& e) {
      return std::string(e.what());
    }
    return std::string("not stopped");
  };
  EXPECT_EQ(stoppedAt(loadSceneByName("jelly"), 0), "stopped while meshing body 'jelly'");  // a surface
  SceneSpec liver = loadSceneByName("liver");
  std::vector<std::pair<double, double>> settled;
  const std::string settling = stoppedAt(liver, 30, &settled);
  EXPECT_EQ(settling.rfind("stopped while settling, ", 0), 0u) << settling;
  ASSERT_FALSE(settled.empty());
  EXPECT_DOUBLE_EQ(settled.back().second, liver.settle);
  for (std::size_t k = 1; k < settled.size(); ++k) EXPECT_GT(settled[k].first, settled[k - 1].first);
  // Five steps into the calibration's poke, once settling is done.
  SceneBuildObserver o;
  bool settledAll = false;
  o.settling = [&](double done, double total) { settledAll = done >= total - 1e-9; };
  o.stop = [&, after = 0]() mutable { return settledAll && ++after > 5; };
  try {
    buildScene(liver, o);
    ADD_FAILURE() << "not stopped";
  } catch (const Stopped& e) {
    EXPECT_STREQ(e.what(), "stopped while calibrating the haptics");
  }
}

TEST(SceneLibrary, UnknownNamesListTheBuiltInScenes) {
  const std::string e = testing::errorOf([] { loadSceneByName("livr"); });
  EXPECT_NE(e.find("no built-in scene 'livr'"), std::string::npos) << e;
  EXPECT_NE(e.find("liver"), std::string::npos) << e;
}

}  // namespace
}  // namespace vrd
