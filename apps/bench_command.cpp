#include "bench_command.h"

#include <fmt/format.h>

#include <chrono>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"
#include "vrdeform/scene/simulation_loop.h"

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

// The liver's haptic loop in real time at 1 kHz for `seconds`, with a reader taking snapshots at
// 90 Hz as a viewer would: with the scene's substeps, and with one (h = 1 ms).
json loop(double seconds, std::string& text) {
  json rows = json::array();
  text +=
      fmt::format("Loop: the liver scene at 1 kHz in real time for {:g} s, a 90 Hz reader taking snapshots\n", seconds);
  text += fmt::format("{:>9} {:>10} | {:>6} {:>10} {:>9} {:>8} | {:>8} {:>8} {:>8}\n", "substeps", "iterations",
                      "steps", "achieved", "overruns", "resyncs", "p50 (ms)", "P99", "max");
  SceneSpec spec = loadSceneByName("liver");
  spec.solver.timeStep = 1e-3f;
  for (int substeps : {spec.solver.substeps, 1}) {
    spec.solver.substeps = substeps;
    BuiltScene scene = buildScene(spec);
    SimulationLoop loop(scene, {});
    const std::shared_ptr<SnapshotChannel> view = loop.subscribe();
    loop.start();
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      view->update();
      std::this_thread::sleep_for(std::chrono::microseconds(11111));
    }
    loop.stop();
    const LoopStats s = loop.stats();
    text += fmt::format("{:>9} {:>10} | {:>6} {:>8.1f}Hz {:>9} {:>8} | {:8.3f} {:8.3f} {:8.3f}\n", substeps,
                        spec.solver.iterations, s.steps, s.achievedRate, s.overruns, s.resyncs, s.stepMs.median,
                        s.stepMs.p99, s.stepMs.max);
    rows.push_back({{"substeps", substeps},
                    {"iterations", spec.solver.iterations},
                    {"steps", s.steps},
                    {"achieved_hz", s.achievedRate},
                    {"overruns", s.overruns},
                    {"resyncs", s.resyncs},
                    {"step_ms", {{"p50", s.stepMs.median}, {"p99", s.stepMs.p99}, {"max", s.stepMs.max}}}});
  }
  text += "  (a step that takes longer than 1 ms is an overrun; far behind, the loop restarts its schedule)\n\n";
  return rows;
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
      s.simd = simd ? SimdLevel::Best : SimdLevel::Off;
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
  j["loop"] = loop(a.quick ? 0.5 : 2.0, text);
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
  cmd->add_flag("--quick", a->quick, "Leave out the 100k-tet scaling row; run the loop for 0.5 s instead of 2");
  return [a]() { return bench(*a); };
}

}  // namespace vrd
