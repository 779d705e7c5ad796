#include "vrdeform/metrics/latency_stats.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace vrd {
namespace {

/// Type-7 percentile of sorted, non-empty `x` at fraction `p` (see summarise()).
double percentile(const std::vector<double>& x, double p) {
  const double h = double(x.size() - 1) * p;
  const std::size_t lo = std::size_t(h);
  if (lo + 1 >= x.size()) return x.back();
  return x[lo] + (h - double(lo)) * (x[lo + 1] - x[lo]);
}

/// summarise() on a vector it may reorder.
SampleStats summariseInPlace(std::vector<double>& x) {
  std::erase_if(x, [](double v) { return !std::isfinite(v); });
  SampleStats s;
  if (x.empty()) return s;
  std::sort(x.begin(), x.end());
  const double n = double(x.size());
  double sum = 0.0;
  for (double v : x) sum += v;
  s.mean = sum / n;
  // Two passes: summing squared deviations avoids the cancellation of E[x^2] - E[x]^2.
  double squares = 0.0;
  for (double v : x) squares += (v - s.mean) * (v - s.mean);
  s.count = x.size();
  s.stddev = std::sqrt(squares / n);
  s.median = percentile(x, 0.50);
  s.p95 = percentile(x, 0.95);
  s.p99 = percentile(x, 0.99);
  s.min = x.front();
  s.max = x.back();
  return s;
}

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

SampleStats summarise(std::span<const double> samples) {
  std::vector<double> x(samples.begin(), samples.end());
  return summariseInPlace(x);
}

void LatencyRecorder::reserve(std::size_t frames) {
  for (auto& rows : rows_) rows.reserve(frames * kColumns);
}

void LatencyRecorder::add(const StageTimes& t, bool contact) {
  auto& rows = rows_[contact ? 1 : 0];
  rows.insert(rows.end(), t.ms.begin(), t.ms.end());
  rows.push_back(t.totalMs());
}

std::size_t LatencyRecorder::frames(Phase p) const {
  const std::size_t idle = rows_[0].size() / kColumns, contact = rows_[1].size() / kColumns;
  return p == Phase::Idle ? idle : p == Phase::Contact ? contact : idle + contact;
}

SampleStats LatencyRecorder::stage(Stage s, Phase p) const { return column(std::size_t(s), p); }

SampleStats LatencyRecorder::total(Phase p) const { return column(kStageCount, p); }

SampleStats LatencyRecorder::column(std::size_t c, Phase p) const {
  std::vector<double> x;
  x.reserve(frames(p));
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    if ((p == Phase::Idle && r == 1) || (p == Phase::Contact && r == 0)) continue;
    for (std::size_t i = c; i < rows_[r].size(); i += kColumns) x.push_back(rows_[r][i]);
  }
  return summariseInPlace(x);
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
