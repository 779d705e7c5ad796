#include "bench_command.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <ranges>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "build_observer.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/metrics/latency_stats.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"
#include "vrdeform/scene/simulation_loop.h"
#include "vrdeform/testing/fake_middleware.h"

namespace vrd {
namespace {

using nlohmann::json;

struct BenchArgs {
  bool json = false;
  int frames = 300;
  bool quick = false;                    // skips the 100k-tet scaling row
  bool smoke = false;                    // every table at its smallest: checks the command, measures nothing
  SimdLevel simd = SimdLevel::Best;      // the lanes of every SIMD figure
  std::vector<std::string> only;         // the parts to run (their JSON keys); empty: all
  const StopSignals* signals = nullptr;  // bench's, for Ctrl-C: each part's loops end early
};

bool stopped(const BenchArgs& a) { return a.signals->requested(); }

// A scene built silently, its settling stopped by Ctrl-C.
BuiltScene benchBuild(const SceneSpec& spec, const BenchArgs& a) {
  return buildScene(spec, commandObserver(*a.signals, false));
}

// A run that Ctrl-C ends after the current step.
RunSettings benchRun(const BenchArgs& a, std::uint64_t steps) {
  RunSettings run;
  run.steps = steps;
  run.afterStep = [&a](const RunStep&) { return !stopped(a); };
  return run;
}

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

// A built-in scene with the lanes asked for (unless the scene runs without lanes).
SceneSpec benchScene(const std::string& name, const BenchArgs& a) {
  SceneSpec spec = loadSceneByName(name);
  if (spec.solver.simd != SimdLevel::Off) spec.solver.simd = a.simd;
  return spec;
}

// Runs `spec` settled, without the hand, for `frames` steps; returns the per-stage statistics.
RunSummary idleRun(SceneSpec spec, int frames, const BenchArgs& a) {
  spec.hand.enabled = false;
  spec.haptics.calibrate = false;
  BuiltScene scene = benchBuild(spec, a);
  return runScene(scene, benchRun(a, std::uint64_t(frames)));
}

double mean(const RunSummary& r, Stage s) { return r.latency.stage(s, Phase::All).mean; }

// Table 1's T_total: the tet constraints and shape matching, in one pass or in the paper's order.
double tetTotal(const RunSummary& r) {
  return mean(r, Stage::Volume) + mean(r, Stage::Strain) + mean(r, Stage::StrainVolume) + mean(r, Stage::ShapeMatching);
}

json table1(const BenchArgs& a, std::string& text) {
  json rows = json::array();
  text += "Table 1: tet bodies, ms per frame (1/60 s), volume + strain + shape matching, 5 iterations\n";
  text +=
      fmt::format("{:<9} {:>5} {:>9} | {:>7} {:>7} {:>7} {:>8} | {:>8} | {:>8} {:>8} | {:>8} {:>7}\n", "scene", "tets",
                  "substeps", "T_v", "T_s", "T_m", "T_total", "fused", "paper", "speed-up", "scene's", "loss");
  for (const PaperRow& p : kTable1) {
    SceneSpec spec = benchScene(p.scene, a);
    const int sceneSubsteps = spec.solver.substeps;
    spec.solver.substeps = 1;  // the paper's setting
    spec.solver.iterations = 5;
    spec.solver.fuseStrainVolume = false;  // and its order, so that T_v and T_s are timed apart
    const RunSummary paperSet = idleRun(spec, a.frames, a);
    spec.solver.fuseStrainVolume = true;
    const RunSummary fusedSet = idleRun(spec, a.frames, a);
    spec.solver.substeps = sceneSubsteps;
    const RunSummary sceneSet = idleRun(spec, a.frames, a);
    const double tv = mean(paperSet, Stage::Volume), ts = mean(paperSet, Stage::Strain),
                 tm = mean(paperSet, Stage::ShapeMatching), total = tv + ts + tm, fused = tetTotal(fusedSet),
                 sceneTotal = tetTotal(sceneSet);
    text += fmt::format(
        "{:<9} {:>5} {:>9} | {:7.4f} {:7.4f} {:7.4f} {:8.4f} | {:8.4f} | {:8.3f} {:7.0f}x | {:8.4f} {:6.2f}%\n",
        p.scene, paperSet.tets, 1, tv, ts, tm, total, fused, p.total, p.total / fused, sceneTotal,
        100 * sceneSet.volumeLossMax);
    rows.push_back({{"scene", p.scene},
                    {"tets", paperSet.tets},
                    {"paper_tets", p.tets},
                    {"T_v", tv},
                    {"T_s", ts},
                    {"T_m", tm},
                    {"T_total", total},
                    {"T_total_fused", fused},
                    {"paper_T_total", p.total},
                    {"speedup", p.total / fused},
                    {"scene_substeps", sceneSubsteps},
                    {"scene_T_total", sceneTotal},
                    {"scene_volume_loss_max", sceneSet.volumeLossMax}});
  }
  text +=
      "  (T_* at the paper's 1 substep and in its order, all strain constraints then all volume ones; \"fused\": "
      "T_total with each tet's strain and volume in one pass, the default, against which the speed-up; "
      "\"scene's\": that at the scene file's substeps, with its volume loss)\n\n";
  return rows;
}

json table2(const BenchArgs& a, std::string& text) {
  SceneSpec spec = benchScene("flag", a);
  spec.solver.substeps = 1;  // the paper's settings
  spec.solver.iterations = 2;
  const RunSummary r = idleRun(spec, a.frames, a);
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

json table3(const BenchArgs& a, std::string& text) {
  BuiltScene scene = benchBuild(benchScene("liver", a), a);
  const RunSummary r = runScene(
      scene, benchRun(a, a.smoke ? std::uint64_t(a.frames)
                                 : std::uint64_t(std::llround(scene.spec.seconds / scene.spec.solver.timeStep))));
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

// How converged the solve is (StepReport::residuals) against the iterations it gets: the liver
// settled on the ground, at its substeps, the largest correction of each stage's last iteration
// (relative to the mean rest edge), its largest over the frames.
json convergence(const BenchArgs& a, std::string& text) {
  json rows = json::array();
  text += "Convergence: the settled liver at its substeps, the last iteration's largest correction / mean rest edge\n";
  text += fmt::format("{:>10} | {:>14} {:>14} {:>14}\n", "iterations", "strain_volume", "shape_matching", "contact");
  for (int iterations : {5, 10, 20, 40}) {
    if (a.smoke && iterations > 10) continue;
    SceneSpec spec = benchScene("liver", a);
    spec.solver.iterations = iterations;
    spec.solver.measureResiduals = true;
    const RunSummary r = idleRun(spec, a.frames, a);
    const auto max = [&](Stage s) { return r.residuals[std::size_t(s)].max; };
    text += fmt::format("{:>10} | {:14.2e} {:14.2e} {:14.2e}\n", iterations, max(Stage::StrainVolume),
                        max(Stage::ShapeMatching), max(Stage::Contact));
    rows.push_back({{"iterations", iterations},
                    {"strain_volume_max", max(Stage::StrainVolume)},
                    {"shape_matching_max", max(Stage::ShapeMatching)},
                    {"contact_max", max(Stage::Contact)}});
  }
  text += "  (0 at a fixed point of the solver; the contact row mirrors the tets': the ground undoes what they do)\n\n";
  return rows;
}

// What the poking finger feels (metrics/signal_quality.h): each tet scene's scripted poke with the
// scene as it is, and with the previous defaults (frictionless fingertips, the paper's smoothing,
// alpha_t 0.2, a poke at constant speed, and each substep's solve started cold), side by side. Runs until 0.3 s after
// the poke's release.
json signalQualityTable(const BenchArgs& a, std::string& text) {
  text += "Signal: the index finger during each scene's scripted poke (newtons | normalised)\n";
  text +=
      fmt::format("{:<9} {:<9} | {:>6} {:>8} {:>6} {:>4} {:>8} | {:>6} {:>8} {:>6} {:>4} {:>6}\n", "scene", "defaults",
                  "rough", "Spearman", "noise", "lag", "peak N", "rough", "Spearman", "noise", "lag", "peak");
  json rows = json::array();
  const auto figures = [](const SignalQuality& q) {
    return json{{"roughness", q.roughness},
                {"loading_spearman", q.loadingSpearman},
                {"hold_noise", q.holdNoise},
                {"lag_steps", q.lagSteps},
                {"peak", q.peak}};
  };
  for (const PaperRow& p : kTable1) {
    if (a.smoke && std::string_view(p.scene) != "liver") continue;
    for (const bool previous : {false, true}) {
      SceneSpec spec = benchScene(p.scene, a);
      if (previous) {
        spec.haptics.settings.signal.alphaT = 0.2f;
        spec.solver.warmStart = false;
        for (ActionSpec& action : spec.hand.actions) action.action.profile = PokeProfile::Linear;
      }
      double end = 0.0;
      for (const ActionSpec& action : spec.hand.actions)
        if (action.action.kind == ActionKind::Poke) end = action.action.end() + 0.3;
      BuiltScene scene = benchBuild(spec, a);  // calibrated as now
      if (previous) scene.session.hand.friction = {};
      const RunSummary r = runScene(scene, benchRun(a, std::uint64_t(std::ceil(end / spec.solver.timeStep))));
      if (r.pokes.empty()) continue;
      const SignalQuality &n = r.pokes[0].newtons, &f = r.pokes[0].force;
      text +=
          fmt::format("{:<9} {:<9} | {:6.2f} {:8.3f} {:5.1f}% {:4} {:8.3f} | {:6.2f} {:8.3f} {:5.1f}% {:4} {:6.3f}\n",
                      p.scene, previous ? "previous" : "now", n.roughness, n.loadingSpearman, 100 * n.holdNoise,
                      n.lagSteps, n.peak, f.roughness, f.loadingSpearman, 100 * f.holdNoise, f.lagSteps, f.peak);
      rows.push_back({{"scene", p.scene},
                      {"defaults", previous ? "previous" : "now"},
                      {"newtons", figures(n)},
                      {"normalised", figures(f)}});
    }
  }
  text +=
      "  (roughness: total variation / 2 peak, 1 for one clean rise and fall; Spearman: force against depth while "
      "loading; noise: sd / mean while holding; lag: steps behind the depth; previous: frictionless fingertips, "
      "alpha_t 0.2, a poke at constant speed, a cold start; the calibration as now, the standard poke at 0.45)\n\n";
  return rows;
}

// The liver's haptic loop in real time at 1 kHz for `seconds`, with a reader taking snapshots at
// 90 Hz as a viewer would: with the scene's substeps, and with one (h = 1 ms).
json loop(const BenchArgs& a, std::string& text) {
  const double seconds = a.smoke ? 0.05 : a.quick ? 0.5 : 2.0;
  json rows = json::array();
  text +=
      fmt::format("Loop: the liver scene at 1 kHz in real time for {:g} s, a 90 Hz reader taking snapshots\n", seconds);
  text += fmt::format("{:>9} {:>10} | {:>6} {:>10} {:>9} {:>8} | {:>8} {:>8} {:>8}\n", "substeps", "iterations",
                      "steps", "achieved", "overruns", "resyncs", "p50 (ms)", "P99", "max");
  SceneSpec spec = benchScene("liver", a);
  spec.solver.timeStep = 1e-3;
  if (a.smoke) {  // at 1 kHz the settle and the calibration's poke take seconds
    spec.settle = 0.05;
    spec.haptics.calibrate = false;
  }
  for (int substeps : {spec.solver.substeps, 1}) {
    if (a.smoke && substeps != spec.solver.substeps) continue;
    spec.solver.substeps = substeps;
    BuiltScene scene = benchBuild(spec, a);
    SimulationLoop loop(scene, {});
    const std::shared_ptr<SnapshotChannel> view = loop.subscribe();
    loop.start();
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end && !stopped(a)) {
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

// Threads that spin until destroyed: the other programs of a VR machine (a compositor, a browser).
class BusyNeighbours {
 public:
  explicit BusyNeighbours(int n) {
    for (int k = 0; k < n; ++k)
      threads_.emplace_back([this] {
        volatile double x = 1.0;
        while (!stop_.load(std::memory_order_relaxed)) x = x * 1.0000001 + 1e-9;
      });
  }
  ~BusyNeighbours() {
    stop_ = true;
    for (std::thread& t : threads_) t.join();
  }
  BusyNeighbours(const BusyNeighbours&) = delete;
  BusyNeighbours& operator=(const BusyNeighbours&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
};

// Motion to force: the liver in the 1 kHz loop with its hand on a (fake) WEART glove. The index
// presses for 30 ms of every 100 and is open otherwise; each press is timed from the tracking frame
// that first shows it leaving the fake middleware to the first force frame for the index that rises,
// as the fake receives it: the client, the loop's wait for its next step, the step and both loopback
// hops. The open 70 ms let the smoothed force fall, so the first rise is the press's answer.
struct MotionToForce {
  SampleStats ms;  // per answered press
  std::size_t unanswered = 0;
  SampleStats stepMs;  // the loop's
};

MotionToForce motionToForceRun(BuiltScene& scene, double seconds, const BenchArgs& a) {
  using Clock = std::chrono::steady_clock;
  constexpr double kCycle = 0.1, kPress = 0.03;
  std::vector<Clock::time_point> presses;  // written on the fake's thread until it stops
  bool pressing = false;
  weart::FakeMiddlewareSettings fs;
  fs.tracking = [&](double t) {
    const bool press = std::fmod(t, kCycle) < kPress;
    if (press && !pressing) presses.push_back(Clock::now());
    pressing = press;
    std::array<float, kFingerCount> closure{};
    closure[std::size_t(Finger::Index)] = press ? 0.5f : 0.0f;  // 0.5: half a fingertip radius deep
    return closure;
  };
  weart::FakeMiddleware fake(fs);
  fake.start();
  const Vec3 point = scene.actions.empty() ? scene.bodies.front().top : scene.actions.front().target;
  GloveLink glove(fmt::format("127.0.0.1:{}", fake.port()), scene.session.hand, point, [](std::string_view, bool) {});
  for (const auto deadline = Clock::now() + std::chrono::seconds(5); !glove.closure(Finger::Index);) {
    if (stopped(a)) throw Stopped("bench: stopped");
    if (Clock::now() > deadline) throw Error("bench: the fake WEART middleware sent no tracking");
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  SimulationLoopSettings ls;
  ls.input = &glove.input();
  ls.outputs = {&glove.output()};
  SimulationLoop loop(scene, ls);
  loop.start();
  const Clock::time_point from = Clock::now() + std::chrono::milliseconds(200);  // past the first steps
  const Clock::time_point until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (Clock::now() < until && !stopped(a)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  loop.stop();
  glove.shutdown();
  fake.stop();

  std::vector<std::pair<Clock::time_point, float>> force;  // the index's force frames as received
  for (const weart::ReceivedCommand& r : fake.commands())
    if (r.command.point == weart::Point::Index && (r.command.kind == weart::ClientCommand::Kind::Force ||
                                                   r.command.kind == weart::ClientCommand::Kind::StopForce))
      force.emplace_back(r.time, r.command.kind == weart::ClientCommand::Kind::Force ? r.command.value : 0.0f);
  MotionToForce out;
  std::vector<double> ms;
  for (const Clock::time_point press : presses) {
    if (press < from || press > until - std::chrono::milliseconds(50)) continue;
    auto next = std::find_if(force.begin(), force.end(), [&](const auto& f) { return f.first > press; });
    const float before = next == force.begin() ? 0.0f : std::prev(next)->second;
    next = std::find_if(next, force.end(), [&](const auto& f) { return f.second > before; });
    if (next == force.end() || next->first - press > std::chrono::duration<double>(kPress))
      ++out.unanswered;
    else
      ms.push_back(std::chrono::duration<double, std::milli>(next->first - press).count());
  }
  out.ms = summarise(ms);
  out.stepMs = loop.stats().stepMs;
  return out;
}

json motionToForce(const BenchArgs& a, std::string& text) {
  const double seconds = a.smoke ? 0.3 : a.quick ? 3.0 : 10.0;
  SceneSpec spec = benchScene("liver", a);
  // At 1 kHz, substeps no longer than the scene's own (one, for the liver's 8 at 60 Hz).
  const double substep = spec.solver.timeStep / spec.solver.substeps;
  spec.solver.timeStep = 1e-3;
  spec.solver.substeps = std::max(1, int(std::ceil(spec.solver.timeStep / substep - 1e-9)));
  if (a.smoke) {
    spec.settle = 0.05;
    spec.haptics.calibrate = false;
  }
  BuiltScene scene = benchBuild(spec, a);
  text += fmt::format(
      "Motion to force: the liver at 1 kHz ({} x {}), its hand on a fake WEART glove (100 Hz tracking), the index "
      "pressing: from the tracking frame leaving the fake middleware to the force frame that answers it arriving "
      "there, ms (target P99 2.0), beside the loop's step\n"
      "{:>11} | {:>7} {:>10} | {:>8} {:>8} {:>8} | {:>9} {:>8}\n",
      spec.solver.substeps, spec.solver.iterations, "neighbours", "presses", "unanswered", "P50", "P99", "max",
      "step P50", "P99");
  json rows = json::array();
  for (int neighbours : {0, 2}) {
    if (a.smoke && neighbours > 0) continue;
    const BusyNeighbours busy(neighbours);
    const MotionToForce m = motionToForceRun(scene, seconds, a);
    text += fmt::format("{:>11} | {:>7} {:>10} | {:8.3f} {:8.3f} {:8.3f} | {:9.3f} {:8.3f}\n", neighbours, m.ms.count,
                        m.unanswered, m.ms.median, m.ms.p99, m.ms.max, m.stepMs.median, m.stepMs.p99);
    rows.push_back({{"neighbours", neighbours},
                    {"presses", m.ms.count},
                    {"unanswered", m.unanswered},
                    {"ms", {{"p50", m.ms.median}, {"p99", m.ms.p99}, {"max", m.ms.max}}},
                    {"step_ms", {{"p50", m.stepMs.median}, {"p99", m.stepMs.p99}}}});
  }
  text += "  (neighbours: threads spinning beside it, as a compositor or a browser would)\n\n";
  return rows;
}

// A block of tets resting on the ground in a world of its own.
struct Block {
  std::unique_ptr<World> world;
  BodyId body = 0;
  std::size_t tets = 0;
};

Block block(const TetMesh& mesh, const Material& material, const ConstraintSet& set, const SolverSettings& settings) {
  Block b{std::make_unique<World>(settings)};
  const auto model = makeSoftBody(mesh, material, set);
  b.tets = model->tets.size();
  b.body = b.world->addBody(model);
  b.world->addCollider(Collider::plane(Vec3::UnitY()));
  return b;
}

Material softMaterial() {
  Material m;
  m.elastic = ElasticModuli{2e4f, 0.45f, 1000.0f, 0.002f};
  return m;
}

// Wall time of world.step(), mean over `frames` after a few warm-up steps (ms).
double msPerStep(World& world, int frames, const BenchArgs& a) {
  for (int k = 0; k < 5; ++k) world.step();
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < frames && !stopped(a); ++k) world.step();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / frames;
}

json scaling(const BenchArgs& a, std::string& text) {
  json rows = json::array();
  const char* lanes = simdName(resolveSimd(a.simd));
  text += fmt::format(
      "Scaling: a block of tets on the ground, volume + strain + shape matching, 1 substep x 5 iterations, ms per "
      "step\n{:>8} | {:>10} {:>10} | {:>10} {:>10} | {:>8} {:>8}\n",
      "tets", "scalar 1t", "scalar 2t", fmt::format("{} 1t", lanes), fmt::format("{} 2t", lanes), "SIMD", "2 thr");
  for (int tets : {1000, 10000, 100000}) {
    if ((a.quick && tets > 10000) || (a.smoke && tets > 1000)) continue;
    const TetMesh mesh = makeBoxTetsNear(Vec3::Zero(), Vec3(0.2f, 0.1f, 0.2f), tets);
    double ms[2][2] = {};  // [simd][threads - 1]
    std::size_t n = 0;
    for (int simd = 0; simd < 2; ++simd)
      for (int threads = 1; threads <= 2; ++threads) {
        SolverSettings s;
        s.simd = simd ? a.simd : SimdLevel::Off;
        s.fuseStrainVolume = simd;  // scalar: the paper's order, the baseline
        s.threads = threads;
        s.threadsFallBack = false;  // the team's figure
        s.timeStages = false;
        Block b = block(mesh, softMaterial(), ConstraintSet::paper(), s);
        n = b.tets;
        ms[simd][threads - 1] = msPerStep(*b.world, std::max(10, a.frames * 1000 / tets), a);
      }
    text += fmt::format("{:>8} | {:10.3f} {:10.3f} | {:10.3f} {:10.3f} | {:7.2f}x {:7.2f}x\n", n, ms[0][0], ms[0][1],
                        ms[1][0], ms[1][1], ms[0][0] / ms[1][0], ms[1][0] / ms[1][1]);
    rows.push_back({{"tets", n},
                    {"lanes", lanes},
                    {"scalar_1t_ms", ms[0][0]},
                    {"scalar_2t_ms", ms[0][1]},
                    {"simd_1t_ms", ms[1][0]},
                    {"simd_2t_ms", ms[1][1]}});
  }
  text += "  (SIMD: the lanes' speed-up on one thread; 2 thr: the second thread's, with SIMD)\n\n";
  return rows;
}

// The poked blocks: a 20 cm cube of 12^3 cells (10,368 tets) and of 17 x 17 x 18 (31,212).
constexpr std::array<int, 3> k10k{12, 12, 12}, k30k{17, 17, 18};

// A full haptic step on a block of `cells`: predict, contacts with the ground and a fingertip
// pressing into the top, solve, haptic force. Per-step wall times (ms) over `frames` steps of the poke.
std::vector<double> pokedBlockSteps(SolverSettings s, std::array<int, 3> cells, int frames, const BenchArgs& a) {
  s.linearDamping = 1.0f;
  Block b = block(makeBoxTets(Vec3(-0.1f, 0.0f, -0.1f), Vec3::Constant(0.2f), cells[0], cells[1], cells[2]),
                  softMaterial(), ConstraintSet::paper(), s);
  for (int k = 0; k < 30; ++k) b.world->step();  // settle a little
  const float top = bodyBounds(*b.world, b.body).max().y();
  const float r = HandGeometry::average().fingertipRadius;
  auto frame = [&](float depth) {
    HandFrame f;
    f.direct = true;
    f.fingertips = {Vec3(0.3f, 1, 0), Vec3(0.0f, top + r - depth, 0.0f), Vec3(0.4f, 1, 0), Vec3(0.5f, 1, 0),
                    Vec3(0.6f, 1, 0)};
    return f;
  };
  HapticSession session(*b.world, {}, frame(-0.005f));
  std::vector<double> ms;
  // At least one sample, stopped or not.
  for (int k = 0; k < frames && (k == 0 || !stopped(a)); ++k) {
    const float depth = -0.005f + 0.02f * float(std::min(k, frames / 2)) / float(frames / 2);  // down 2 cm, hold
    const auto start = std::chrono::steady_clock::now();
    session.step(frame(depth));
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  return ms;
}

// The 105k-tet cube of the targets: 1 m, 26^3 cells, stiff (E = 10 MPa), edges + volume, on the
// ground.
Block cube(const SolverSettings& s) {
  Material stiff;
  stiff.elastic = ElasticModuli{1e7f, 0.3f, 1000.0f, 0.0f};
  return block(makeBoxTets(Vec3(-0.5f, 0.0f, -0.5f), Vec3::Ones(), 26, 26, 26), stiff, ConstraintSet::edgesAndVolume(),
               s);
}

// Mean and 90th percentile of per-step times.
std::pair<double, double> meanAndP90(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  double sum = 0.0;
  for (double v : ms) sum += v;
  return {sum / double(ms.size()), ms[ms.size() * 9 / 10]};
}

// The solver's threads beside busy neighbours (issue 32): the 10k-tet haptic step and the 105k
// cube with 0 and 2 spinning threads beside, on one thread, on two always (the team every step:
// the baseline) and on two with the fallback to one (the default), timed after some steps in which
// the fallback makes its first choice.
json contention(const BenchArgs& a, std::string& text) {
  text += fmt::format(
      "Contention: mean / P90 ms per step beside N threads spinning (other programs), {} lanes\n{:>34} | {:>15} {:>15} "
      "{:>15} | {:>8}\n",
      simdName(resolveSimd(a.simd)), "body, neighbours", "1 thread", "2 always", "2 fallback", "fb / 1t");
  json rows = json::array();
  const int frames = a.smoke ? a.frames : std::max(300, a.frames);
  for (const bool big : {false, true}) {
    if (big && a.quick) continue;
    for (const int neighbours : {0, 2}) {
      std::pair<double, double> ms[3];
      for (int mode = 0; mode < 3; ++mode) {
        SolverSettings s;
        s.simd = a.simd;
        s.threads = mode == 0 ? 1 : 2;
        s.threadsFallBack = mode == 2;
        s.timeStages = false;
        if (big) s.substeps = 5, s.iterations = 1;
        const BusyNeighbours busy(neighbours);
        if (big) {
          Block b = cube(s);
          for (int k = 0; k < 64; ++k) b.world->step();  // as the poked block's settling: the choice is made
          std::vector<double> steps;
          for (int k = 0; k < frames / 3 && (k == 0 || !stopped(a)); ++k) {
            const auto start = std::chrono::steady_clock::now();
            b.world->step();
            steps.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
          }
          ms[mode] = meanAndP90(std::move(steps));
        } else {
          ms[mode] = meanAndP90(pokedBlockSteps(s, k10k, frames, a));
        }
      }
      const std::string name =
          fmt::format("{}, {}", big ? "105k cube, 5 x 1" : "10k poked, paper set, 5 it", neighbours);
      text +=
          fmt::format("{:>34} | {:7.3f} /{:6.3f} {:7.3f} /{:6.3f} {:7.3f} /{:6.3f} | {:7.2f}x\n", name, ms[0].first,
                      ms[0].second, ms[1].first, ms[1].second, ms[2].first, ms[2].second, ms[2].first / ms[0].first);
      rows.push_back({{"body", big ? "cube_105k" : "poked_10k"},
                      {"neighbours", neighbours},
                      {"mean_1t_ms", ms[0].first},
                      {"p90_1t_ms", ms[0].second},
                      {"mean_2t_always_ms", ms[1].first},
                      {"p90_2t_always_ms", ms[1].second},
                      {"mean_2t_fallback_ms", ms[2].first},
                      {"p90_2t_fallback_ms", ms[2].second}});
    }
  }
  text +=
      "  (2 always: the team every step; 2 fallback: one thread while that has lately been faster, the default)\n\n";
  return rows;
}

// Sag and worst edge strain of a settled block: how far the top fell (m) and max |l/l0 - 1|.
std::pair<double, double> sagAndStrain(const World& world, BodyId body, float restTop) {
  const Body& b = world.body(body);
  const Point* x = world.particles().x.data() + b.firstParticle;
  double topSum = 0, worst = 0;
  int topCount = 0;
  for (Index i = 0; i < b.particleCount; ++i)
    if (b.model->restPositions[i].y() > restTop - 1e-4f) topSum += x[i].pos.y(), ++topCount;
  for (const DistanceConstraint& c : b.model->distance)
    worst = std::max(worst, std::abs(double((x[c.i[0]].pos - x[c.i[1]].pos).norm()) / c.restLength - 1.0));
  return {restTop - topSum / std::max(topCount, 1), worst};
}

// Issues 6's and 32's targets, each measured here (2-core machine like CI).
json targets(const BenchArgs& a, const json& table1Rows, std::string& text) {
  text += "Targets (issues 6 and 32)\n";
  json out;
  // Paper-sized body, one core: the furball's Table 1 row (1,297 tets, the paper's constraints),
  // with the default solver (strain and volume in one pass).
  for (const json& row : table1Rows)
    if (row["scene"] == "furball") {
      const double ms = row["T_total_fused"];
      text += fmt::format("  paper-sized body ({} tets), 1 core, 5 iterations: {:.3f} ms per step (target 0.1)\n",
                          row["tets"].get<std::size_t>(), ms);
      out["paper_body"] = {{"tets", row["tets"]}, {"ms", ms}, {"target_ms", 0.1}};
    }

  // 10k and 30k tets, a whole haptic step at the loop's rate.
  const int frames = a.smoke ? a.frames : std::max(60, a.frames);
  for (const auto& [cells, key] : {std::pair{k10k, "10k_full_step"}, std::pair{k30k, "30k_full_step"}}) {
    if (a.quick && cells == k30k) continue;
    const std::size_t tets = 6 * std::size_t(cells[0] * cells[1] * cells[2]);
    SolverSettings s;
    s.simd = a.simd;
    s.threads = 1;
    const SampleStats one = summarise(pokedBlockSteps(s, cells, frames, a));
    s.threads = 2;
    s.threadsFallBack = false;  // the team's figure
    const SampleStats two = summarise(pokedBlockSteps(s, cells, frames, a));
    text += fmt::format(
        "  {} tets pressed by a fingertip, full step (predict, contacts, solve, force): P99 {:.3f} ms on 2 threads "
        "(mean {:.3f}), {:.3f} ms on 1 (mean {:.3f}); target P99 1.0 ms\n",
        tets, two.p99, two.mean, one.p99, one.mean);
    out[key] = {{"tets", tets},         {"p99_2t_ms", two.p99},   {"mean_2t_ms", two.mean},
                {"p99_1t_ms", one.p99}, {"mean_1t_ms", one.mean}, {"target_p99_ms", 1.0}};
  }

  // 100k tets: a 1 m cube of 26^3 cells, stiff (E = 10 MPa), edges + volume, 2 s on the ground, with a
  // budget of 5 projections of each constraint per step: as 5 substeps x 1 iteration ("small steps",
  // which converge far better) and as 1 x 5.
  if (!a.quick) {
    for (auto [substeps, iterations, threads] : {std::tuple{5, 1, 2}, std::tuple{5, 1, 1}, std::tuple{1, 5, 1}}) {
      SolverSettings s;
      s.simd = a.simd;
      s.substeps = substeps;
      s.iterations = iterations;
      s.threads = threads;
      s.threadsFallBack = false;
      s.timeStages = false;
      Block b = cube(s);
      const double ms = msPerStep(*b.world, 115, a);  // 5 + 115 steps: 2 s
      const auto [sag, strain] = sagAndStrain(*b.world, b.body, 1.0f);
      const double perTet = double(b.world->bodyBytes(b.body)) / double(b.tets);
      text += fmt::format(
          "  {} tets (1 m cube, E = 10 MPa), edges + volume, {} x {}, {} thread{}: {:.3f} ms per step (target 2.5 on "
          "2 threads); after 2 s: sag {:.1f} mm, worst edge strain {:.1f}%; {:.0f} bytes per tet (target 300)\n",
          b.tets, substeps, iterations, threads, threads > 1 ? "s" : "", ms, 1e3 * sag, 100 * strain, perTet);
      out["100k"].push_back({{"tets", b.tets},
                             {"substeps", substeps},
                             {"iterations", iterations},
                             {"threads", threads},
                             {"ms", ms},
                             {"sag_m", sag},
                             {"worst_edge_strain", strain},
                             {"bytes_per_tet", perTet},
                             {"target_ms", 1.5}});
    }
  }
  text += "\n";
  return out;
}

// The machine the figures come from: they differ by 2x between CPUs of the same kind (with and
// without AVX-512, say), so a table means little without it.
struct Machine {
  std::string cpu = "unknown CPU";  // /proc/cpuinfo's model name
  unsigned threads = std::thread::hardware_concurrency();
  std::string lanes;  // those the figures used

  explicit Machine(SimdLevel simd) : lanes(simdName(resolveSimd(simd))) {
    std::ifstream info("/proc/cpuinfo");
    for (std::string line; std::getline(info, line);)
      if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
        cpu = line.substr(line.find(':') + 1);
        cpu.erase(0, cpu.find_first_not_of(' '));
        return;
      }
  }
};

int bench(BenchArgs a) {
  std::string text;
  json j;
  if (!cpuSupports(a.simd)) throw Error(fmt::format("bench: this CPU has no {} lanes", simdName(a.simd)));
  const StopSignals signals;
  a.signals = &signals;
  const Machine m(a.simd);
  j["machine"] = {{"cpu", m.cpu}, {"hardware_threads", m.threads}, {"lanes", m.lanes}};
  j["frames"] = a.frames;
  const auto print = [&] {
    if (a.json)
      fmt::print("{}\n", j.dump(2));
    else
      fmt::print(
          "{}The paper: Unity/C# on an i7-13700K. Here: {} ({} hardware threads, {} lanes), one thread unless a row "
          "says otherwise.\n",
          text, m.cpu, m.threads, m.lanes);
  };
  // Each part with its progress on stderr, so that it neither mixes with --json nor stays on a page
  // of results. Ctrl-C ends the part that runs early; what it measured is dropped, and the parts
  // done before it are printed.
  using Measure = std::function<json()>;
  const std::vector<std::tuple<const char*, std::string_view, Measure>> parts = {
      {"table1", "Table 1: the paper's scenes", [&] { return table1(a, text); }},
      {"table2", "Table 2: the flag", [&] { return table2(a, text); }},
      {"table3", "Table 3: the liver's stages", [&] { return table3(a, text); }},
      {"loop", "the real-time loop", [&] { return loop(a, text); }},
      {"motion_to_force", "motion to force", [&] { return motionToForce(a, text); }},
      {"scaling", "scaling", [&] { return scaling(a, text); }},
      {"targets", "targets", [&] { return targets(a, j["table1"], text); }},
      {"contention", "contention", [&] { return contention(a, text); }},
      {"signal", "signal quality", [&] { return signalQualityTable(a, text); }},
      {"convergence", "convergence", [&] { return convergence(a, text); }},
  };
  for (const std::string& key : a.only)
    if (std::ranges::none_of(parts, [&](const auto& p) { return key == std::get<0>(p); }))
      throw Error(
          fmt::format("bench: --only: no part '{}' (the parts: {})", key,
                      fmt::join(parts | std::views::transform([](const auto& p) { return std::get<0>(p); }), ", ")));
  const auto chosen = [&](const char* key) { return a.only.empty() || std::ranges::count(a.only, key) > 0; };
  const auto count = std::ranges::count_if(parts, [&](const auto& p) { return chosen(std::get<0>(p)); });
  int done = 0;
  for (const auto& [key, what, measure] : parts) {
    if (!chosen(key)) continue;
    fmt::print(stderr, "bench [{}/{}] {}...\n", done + 1, count, what);
    std::fflush(stderr);
    const std::string before = text;
    json result;
    try {
      result = measure();
    } catch (const Stopped&) {  // while a scene settled
    }
    if (stopped(a)) {
      text = before;
      print();
      throw Stopped(fmt::format("bench: stopped during {} ({} of {} parts done)", what, done, count));
    }
    j[key] = std::move(result);
    ++done;
  }
  print();
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
  cmd->add_flag_callback(
      "--smoke",
      [a] {
        a->smoke = a->quick = true;
        a->frames = 2;
      },
      "Every table at its smallest (2 frames, the loop for 0.05 s, 1k tets): checks that the command runs, "
      "measures nothing");
  cmd->add_option("--only", a->only, "Run only these parts (keys of --json's output: table1, loop, signal, ...)");
  cmd->add_option_function<std::string>(
         "--simd",
         [a](const std::string& name) {
           for (SimdLevel level : {SimdLevel::Best, SimdLevel::Avx512, SimdLevel::Avx2, SimdLevel::Sse})
             if (name == simdName(level)) a->simd = level;
         },
         "Lanes of the SIMD figures: best (the widest this CPU has), avx512, avx2 or sse; a narrower set than the "
         "CPU's shows what a machine without the wider one would get")
      ->check(CLI::IsMember({"best", "avx512", "avx2", "sse"}))
      ->default_str("best");
  return [a]() { return bench(*a); };
}

}  // namespace vrd
