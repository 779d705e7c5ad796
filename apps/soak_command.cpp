#include "soak_command.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "build_observer.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/sample_stats.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {
namespace {

struct SoakArgs {
  std::string scene = "liver", out;
  std::uint64_t steps = 1'000'000;
  int rows = 20;
  double rest = 1.0;      // s between the end of one round of actions and the start of the next
  double p99Rise = 1.25;  // largest allowed ratio of the late half's step P99 to the early half's
};

/// The pass marks (docs/loop.md): memory growth per million steps after warm-up, volume drift
/// between the ends of the first and the last round after warm-up.
constexpr double kMaxGrowthPerMillion = 1 << 20;  // bytes
constexpr double kMaxVolumeDrift = 1e-4;          // 0.01%
/// The fewest warm-up steps: the run's bounded buffers (the plots' points, the statistics' exact
/// samples) fill up over the first ones.
constexpr std::uint64_t kMinWarmUp = 20'000;

/// This process's resident memory (bytes), from /proc/self/statm; 0 where there is none.
double residentBytes() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0.0;
  unsigned long size = 0, resident = 0;
  const bool read = std::fscanf(f, "%lu %lu", &size, &resident) == 2;
  std::fclose(f);
  return read ? double(resident) * double(sysconf(_SC_PAGESIZE)) : 0.0;
}

/// Repeats the scene's scripted actions every `cycle` seconds until `seconds` are covered.
void repeatActions(HandSpec& hand, double cycle, double seconds) {
  const std::vector<ActionSpec> round = hand.actions;
  for (int c = 1; double(c) * cycle < seconds; ++c)
    for (ActionSpec a : round) {
      a.action.start += double(c) * cycle;
      hand.actions.push_back(a);
    }
}

int soak(const SoakArgs& a) {
  if (!a.out.empty()) prepareOutputFolder(a.out);
  SceneSpec spec = loadSceneByName(a.scene);
  if (!spec.hand.enabled || !spec.hand.script.empty() || spec.hand.actions.empty())
    throw Error(fmt::format("soak: scene {} has no scripted hand actions ([[hand.action]]) to repeat", spec.name));
  double cycle = 0.0;
  for (const ActionSpec& s : spec.hand.actions) cycle = std::max(cycle, s.action.end());
  cycle += a.rest;
  const double dt = spec.solver.timeStep, seconds = double(a.steps) * dt;
  const auto cycleSteps = std::uint64_t(std::ceil(cycle / dt));
  const std::uint64_t warm = std::max({a.steps / 10, cycleSteps, kMinWarmUp});
  if (a.steps < warm + 2 * cycleSteps)
    throw Error(
        fmt::format("soak: {} steps are too few: the checks need a warm-up of {} steps (a tenth of the run, at "
                    "least {} and one round of the hand's actions) and two more rounds of {} steps",
                    a.steps, warm, kMinWarmUp, cycleSteps));
  const std::size_t perRound = spec.hand.actions.size();
  repeatActions(spec.hand, cycle, seconds);
  spec.output.meshEvery = 0.0;  // per-step CSVs only: a mesh frame every 0.1 s would fill the disk

  fmt::print(
      "soak: scene {}, {} steps ({:.1f} s simulated); its {} hand actions repeated every {:g} s; warm-up {} "
      "steps\n",
      spec.name, a.steps, seconds, perRound, cycle, warm);
  const StopSignals signals;
  BuiltScene scene = buildScene(spec, commandObserver(signals, false));

  // Watched: resident memory and the step times' statistics per row of the table, the volume
  // loss at the end of each round (the hand away from the body), step times early and late.
  const std::uint64_t every = std::max<std::uint64_t>(1, a.steps / std::uint64_t(std::max(1, a.rows)));
  RunningStats row, early, late;
  double rssWarm = 0.0, rssEnd = 0.0, roundLoss = NAN, firstLoss = NAN, lastLoss = NAN;
  std::uint64_t nan = 0;
  fmt::print("\n{:>10} {:>10} {:>8} {:>9} {:>9} {:>13} {:>5}\n", "step", "time (s)", "RSS (MB)", "mean (ms)",
             "P99 (ms)", "volume loss %", "NaN");
  RunSettings settings;
  settings.steps = a.steps;
  settings.outDir = a.out;
  settings.afterStep = [&](const RunStep& s) {
    const double ms = s.times->totalMs();
    row.add(ms);
    if (s.step >= warm) (s.step < warm + (a.steps - warm) / 2 ? early : late).add(ms);
    if ((s.step + 1) % cycleSteps == 0) {
      roundLoss = s.volumeLoss;
      if (s.step >= warm) {
        if (std::isnan(firstLoss)) firstLoss = roundLoss;
        lastLoss = roundLoss;
      }
    }
    nan = s.nanEvents;
    if (s.step + 1 == warm) rssWarm = residentBytes();
    if ((s.step + 1) % every == 0 || s.step + 1 == a.steps) {
      rssEnd = residentBytes();
      const SampleStats st = row.stats();
      fmt::print("{:>10} {:>10.1f} {:>8.1f} {:>9.4f} {:>9.4f} {:>13.4f} {:>5}\n", s.step + 1, s.time, rssEnd / 1e6,
                 st.mean, st.p99, 100.0 * roundLoss, nan);
      std::fflush(stdout);
      row = RunningStats();
    }
    return !signals.requested();
  };
  RunSummary summary;
  try {
    summary = runScene(scene, settings);
  } catch (const Error& e) {
    fmt::print(stderr, "vrdeform: the soak's run failed: {}\n", e.what());
    return 1;
  }
  if (summary.steps < a.steps) {
    fmt::print("stopped after {} of {} steps: no verdict\n", summary.steps, a.steps);
    return 1;
  }

  const double growth = (rssEnd - rssWarm) / double(a.steps - warm) * 1e6;
  const double drift = std::abs(lastLoss - firstLoss);
  const double p99Early = early.stats().p99, p99Late = late.stats().p99;
  bool pass = true;
  const auto check = [&](bool ok, const std::string& what) {
    fmt::print("  {} {}\n", ok ? "pass" : "FAIL", what);
    pass = pass && ok;
  };
  fmt::print("\n");
  check(growth < kMaxGrowthPerMillion,
        fmt::format("memory after warm-up: {:.1f} -> {:.1f} MB, {:.3f} MB per million steps (< {:g})", rssWarm / 1e6,
                    rssEnd / 1e6, growth / double(1 << 20), kMaxGrowthPerMillion / double(1 << 20)));
  check(summary.nanEvents == 0, fmt::format("NaN events: {}", summary.nanEvents));
  check(drift < kMaxVolumeDrift, fmt::format("volume loss at the end of a round: {:.4f}% first, {:.4f}% last, drift "
                                             "{:.4f}% (< {:g}%)",
                                             100 * firstLoss, 100 * lastLoss, 100 * drift, 100 * kMaxVolumeDrift));
  check(p99Late <= a.p99Rise * p99Early,
        fmt::format("step P99: {:.4f} ms in the early half after warm-up, {:.4f} ms in the late half (at most x{:g})",
                    p99Early, p99Late, a.p99Rise));
  fmt::print("soak: {}\n", pass ? "passed" : "FAILED");
  return pass ? 0 : 1;
}

}  // namespace

std::function<int()> addSoakCommand(CLI::App& app) {
  auto a = std::make_shared<SoakArgs>();
  CLI::App* cmd = app.add_subcommand(
      "soak",
      "Run a scene for long with its scripted hand repeating its actions, checking memory, NaN, volume "
      "drift and step time for growth");
  cmd->add_option("scene", a->scene, "A built-in scene (`vrdeform scenes`) or a scene file (.toml)")
      ->capture_default_str();
  cmd->add_option("--steps", a->steps, "Steps to run after settling")
      ->capture_default_str()
      ->check(CLI::Range(1, 1 << 30));
  cmd->add_option("--out", a->out, "Also write the run's per-step files (forces.csv, stage_times.csv, ...) into DIR");
  cmd->add_option("--rows", a->rows, "Rows of the table over time")->capture_default_str()->check(CLI::Range(1, 1000));
  cmd->add_option("--rest", a->rest, "Seconds between one round of the hand's actions and the next")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  cmd->add_option("--p99-rise", a->p99Rise, "Largest allowed ratio of the late to the early step P99")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  return [a, cmd]() -> int { return *cmd ? soak(*a) : 0; };
}

}  // namespace vrd
