#include "bench_command.h"

#include <fmt/format.h>

#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {
namespace {

using nlohmann::json;

struct BenchArgs {
  bool json = false;
  int frames = 300;
  bool quick = false;  // skips the 100k-tet scaling row
};

// The paper's figures (Tables 1-3), ms per frame, Unity/C# on an i7-13700K.
struct PaperRow {
  const char* scene;
  int tets;
  double tv, ts, tm, total;
};
constexpr PaperRow kTable1[] = {{"furball", 1280, 1.471, 11.972, 0.219, 12.790},
                                {"liver", 770, 0.848, 7.836, 0.120, 8.804},
                                {"balloon", 1713, 1.931, 17.157, 0.233, 19.321},
                                {"jelly", 1530, 1.693, 14.814, 0.226, 16.733},
                                {"bear", 1041, 1.155, 10.467, 0.146, 11.768}};
constexpr double kFlagTc = 0.573, kFlagTb = 0.693, kFlagTotal = 1.266;
constexpr double kIdleTotal = 9.27, kContactTotal = 9.72, kContactP99 = 11.38;

// Runs `spec` settled, without the hand, for `frames` steps; returns the per-stage statistics.
RunSummary idleRun(SceneSpec spec, int frames) {
  spec.hand.enabled = false;
  spec.haptics.calibrate = false;
  BuiltScene scene = buildScene(spec);
  RunSettings run;
  run.steps = std::uint64_t(frames);
  return runScene(scene, run);
}

double mean(const RunSummary& r, Stage s) { return r.latency.stage(s, Phase::All).mean; }

json table1(const BenchArgs& a, std::string& text) {
  json rows = json::array();
  text += "Table 1: tet bodies, ms per frame (1/60 s), volume + strain + shape matching, 5 iterations\n";
  text += fmt::format("{:<9} {:>5} {:>9} | {:>7} {:>7} {:>7} {:>8} | {:>8} {:>8} | {:>8} {:>7}\n", "scene", "tets",
                      "substeps", "T_v", "T_s", "T_m", "T_total", "paper", "speed-up", "scene's", "loss");
  for (const PaperRow& p : kTable1) {
    SceneSpec spec = loadSceneByName(p.scene);
    const int sceneSubsteps = spec.solver.substeps;
    spec.solver.substeps = 1;  // the paper's setting
    spec.solver.iterations = 5;
    const RunSummary paperSet = idleRun(spec, a.frames);
    spec.solver.substeps = sceneSubsteps;
    const RunSummary sceneSet = idleRun(spec, a.frames);
    const double tv = mean(paperSet, Stage::Volume), ts = mean(paperSet, Stage::Strain),
                 tm = mean(paperSet, Stage::ShapeMatching), total = tv + ts + tm;
    const double sceneTotal =
        mean(sceneSet, Stage::Volume) + mean(sceneSet, Stage::Strain) + mean(sceneSet, Stage::ShapeMatching);
    text += fmt::format("{:<9} {:>5} {:>9} | {:7.4f} {:7.4f} {:7.4f} {:8.4f} | {:8.3f} {:7.0f}x | {:8.4f} {:6.2f}%\n",
                        p.scene, paperSet.tets, 1, tv, ts, tm, total, p.total, p.total / total, sceneTotal,
                        100 * sceneSet.volumeLossMax);
    rows.push_back({{"scene", p.scene},
                    {"tets", paperSet.tets},
                    {"paper_tets", p.tets},
                    {"T_v", tv},
                    {"T_s", ts},
                    {"T_m", tm},
                    {"T_total", total},
                    {"paper_T_total", p.total},
                    {"speedup", p.total / total},
                    {"scene_substeps", sceneSubsteps},
                    {"scene_T_total", sceneTotal},
                    {"scene_volume_loss_max", sceneSet.volumeLossMax}});
  }
  text +=
      "  (T_* at the paper's 1 substep; \"scene's\": T_total at the scene file's substeps, with its volume loss)\n\n";
  return rows;
}

json table2(const BenchArgs& a, std::string& text) {
  SceneSpec spec = loadSceneByName("flag");
  spec.solver.substeps = 1;  // the paper's settings
  spec.solver.iterations = 2;
  const RunSummary r = idleRun(spec, a.frames);
  const double tc = mean(r, Stage::Distance), tb = mean(r, Stage::Bend);
  text += "Table 2: the flag (cloth), ms per frame (1/60 s), stretch + bending, 1 substep x 2 iterations\n";
  text += fmt::format("{:<9} {:>7} {:>7} | {:>7} {:>7} {:>8} | {:>8} {:>8}\n", "scene", "N_c", "N_b", "T_c", "T_b",
                      "T_total", "paper", "speed-up");
  text += fmt::format("{:<9} {:>7} {:>7} | {:7.4f} {:7.4f} {:8.4f} | {:8.3f} {:7.0f}x\n\n", "flag",
                      r.constraints.at("distance"), r.constraints.at("bend"), tc, tb, tc + tb, kFlagTotal,
                      kFlagTotal / (tc + tb));
  return {{"N_c", r.constraints.at("distance")},
          {"N_b", r.constraints.at("bend")},
          {"T_c", tc},
          {"T_b", tb},
          {"T_total", tc + tb},
          {"paper_T_c", kFlagTc},
          {"paper_T_b", kFlagTb},
          {"paper_T_total", kFlagTotal}};
}

json table3(std::string& text) {
  BuiltScene scene = buildScene(loadSceneByName("liver"));
  RunSettings run;
  run.steps = std::uint64_t(std::llround(scene.spec.seconds / scene.spec.solver.timeStep));
  const RunSummary r = runScene(scene, run);
  const SampleStats idle = r.latency.total(Phase::Idle), contact = r.latency.total(Phase::Contact);
  text += fmt::format("Table 3: per-stage latency of the liver scene with its poke and grasp, ms ({} frames)\n{}",
                      r.steps, latencyTable(r.latency));
  text += fmt::format(
      "  total: idle mean {:.3f} (paper {:.2f}), contact mean {:.3f} (paper {:.2f}), contact P99 {:.3f} "
      "(paper {:.2f})\n\n",
      idle.mean, kIdleTotal, contact.mean, kContactTotal, contact.p99, kContactP99);
  const auto stats = [](const SampleStats& s) {
    return json{{"frames", s.count}, {"mean", s.mean}, {"p50", s.median}, {"p95", s.p95}, {"p99", s.p99}};
  };
  return {{"idle_total", stats(idle)},
          {"contact_total", stats(contact)},
          {"paper", {{"idle_mean", kIdleTotal}, {"contact_mean", kContactTotal}, {"contact_p99", kContactP99}}}};
}

json scaling(const BenchArgs& a, std::string& text) {
  json rows = json::array();
  text +=
      "Scaling: a block of tets on the ground, volume + strain + shape matching, 1 substep x 5 iterations, 1 thread\n";
  text += fmt::format("{:>8} | {:>12} {:>12} {:>8}\n", "tets", "SIMD (ms)", "scalar (ms)", "ratio");
  for (int tets : {1000, 10000, 100000}) {
    if (a.quick && tets > 10000) continue;
    double ms[2] = {0, 0};
    std::size_t n = 0;
    for (bool simd : {true, false}) {
      SolverSettings s;
      s.simd = simd;
      World world(s);
      Material m;
      m.elastic = ElasticModuli{2e4f, 0.45f, 1000.0f, 0.002f};
      const auto model =
          makeSoftBody(makeBoxTetsNear(Vec3::Zero(), Vec3(0.2f, 0.1f, 0.2f), tets), m, ConstraintSet::paper());
      n = model->tets.size();
      world.addBody(model);
      world.addCollider(Collider::plane(Vec3::UnitY()));
      const int frames = std::max(10, a.frames * 1000 / tets);
      for (int k = 0; k < 5; ++k) world.step();  // warm up
      const auto start = std::chrono::steady_clock::now();
      for (int k = 0; k < frames; ++k) world.step();
      ms[simd ? 0 : 1] =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / frames;
    }
    text += fmt::format("{:>8} | {:12.3f} {:12.3f} {:7.2f}x\n", n, ms[0], ms[1], ms[1] / ms[0]);
    rows.push_back({{"tets", n}, {"simd_ms", ms[0]}, {"scalar_ms", ms[1]}});
  }
  text += "  (threads and graph colouring: issue 6)\n";
  return rows;
}

int bench(const BenchArgs& a) {
  std::string text;
  json j;
  j["frames"] = a.frames;
  j["table1"] = table1(a, text);
  j["table2"] = table2(a, text);
  j["table3"] = table3(text);
  j["scaling"] = scaling(a, text);
  if (a.json)
    fmt::print("{}\n", j.dump(2));
  else
    fmt::print("{}\nThe paper: Unity/C# on an i7-13700K. Here: this machine, one thread.\n", text);
  return 0;
}

}  // namespace

std::function<int()> addBenchCommand(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand("bench", "The paper's Tables 1-3 on the built-in scenes, and solver scaling");
  cmd->add_flag("--json", a->json, "Print the tables as JSON");
  cmd->add_option("--frames", a->frames, "Frames measured per scene")
      ->check(CLI::Range(10, 100000))
      ->capture_default_str();
  cmd->add_flag("--quick", a->quick, "Leave out the 100k-tet scaling row");
  return [a]() { return bench(*a); };
}

}  // namespace vrd
