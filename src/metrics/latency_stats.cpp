#include "vrdeform/metrics/latency_stats.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>

namespace vrd {
namespace {

constexpr Phase kPhases[] = {Phase::Idle, Phase::Contact, Phase::All};

std::string_view phaseName(Phase p) {
  switch (p) {
    case Phase::Idle:
      return "idle";
    case Phase::Contact:
      return "contact";
    case Phase::All:
      return "all";
  }
  return "?";
}

}  // namespace

void LatencyRecorder::add(const StageTimes& t, bool contact) {
  auto& columns = columns_[contact ? 1 : 0];
  for (std::size_t s = 0; s < kStageCount; ++s) columns[s].add(t.ms[s]);
  columns[kStageCount].add(t.totalMs());
}

std::size_t LatencyRecorder::frames(Phase p) const {
  const std::size_t idle = columns_[0][kStageCount].count(), contact = columns_[1][kStageCount].count();
  return p == Phase::Idle ? idle : p == Phase::Contact ? contact : idle + contact;
}

SampleStats LatencyRecorder::stage(Stage s, Phase p) const { return column(std::size_t(s), p); }

SampleStats LatencyRecorder::total(Phase p) const { return column(kStageCount, p); }

SampleStats LatencyRecorder::column(std::size_t c, Phase p) const {
  if (p != Phase::All) return columns_[p == Phase::Contact ? 1 : 0][c].stats();
  RunningStats both = columns_[0][c];
  both.merge(columns_[1][c]);
  return both.stats();
}

std::string latencyTable(const LatencyRecorder& recorder) {
  // The same rows in both blocks, so they line up: stages that took time in any frame.
  std::vector<Stage> stages;
  for (std::size_t s = 0; s < kStageCount; ++s) {
    if (recorder.stage(Stage(s), Phase::All).max > 0.0) stages.push_back(Stage(s));
  }
  fmt::memory_buffer out;
  auto row = [&](std::string_view name, const SampleStats& st) {
    fmt::format_to(std::back_inserter(out), "  {:<16}{:>9.3f}{:>9.3f}{:>9.3f}{:>9.3f}{:>9.3f}\n", name, st.mean,
                   st.median, st.stddev, st.p95, st.p99);
  };
  for (Phase p : {Phase::Idle, Phase::Contact}) {
    const std::size_t frames = recorder.frames(p);
    const std::string_view title = p == Phase::Idle ? "Idle" : "Contact";
    if (frames == 0) {
      fmt::format_to(std::back_inserter(out), "{}: no frames\n", title);
      continue;
    }
    fmt::format_to(std::back_inserter(out), "{}: {} frames, ms\n  {:<16}{:>9}{:>9}{:>9}{:>9}{:>9}\n", title, frames,
                   "stage", "Mean", "Med", "Std", "P95", "P99");
    for (Stage s : stages) row(stageName(s), recorder.stage(s, p));
    row("total", recorder.total(p));
  }
  return fmt::to_string(out);
}

std::string latencyCsv(const LatencyRecorder& recorder) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "phase,stage,frames,mean_ms,median_ms,std_ms,p95_ms,p99_ms,min_ms,max_ms\n");
  auto row = [&](Phase p, std::string_view name, const SampleStats& st) {
    fmt::format_to(std::back_inserter(out), "{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", phaseName(p),
                   name, st.count, st.mean, st.median, st.stddev, st.p95, st.p99, st.min, st.max);
  };
  for (Phase p : kPhases) {
    for (std::size_t s = 0; s < kStageCount; ++s) row(p, stageName(Stage(s)), recorder.stage(Stage(s), p));
    row(p, "total", recorder.total(p));
  }
  return fmt::to_string(out);
}

}  // namespace vrd
