#pragma once
// Latency statistics per stage, for frames without and with contact (paper Table 3).

#include <array>
#include <cstddef>
#include <string>

#include "vrdeform/metrics/sample_stats.h"
#include "vrdeform/metrics/stage_times.h"

namespace vrd {

/// Which frames a statistic covers.
enum class Phase {
  Idle,     ///< frames without contact
  Contact,  ///< frames with contact
  All       ///< both
};

/// Per-stage times of any number of frames, kept apart for idle and contact frames, in fixed memory
/// (RunningStats: percentiles exact for the first frames of each phase, then within 1.1%). Adding
/// a frame never allocates.
class LatencyRecorder {
 public:
  /// Records one frame's per-stage times and their total (t.totalMs()).
  void add(const StageTimes& t, bool contact);

  SampleStats stage(Stage s, Phase p) const;
  /// Statistics of the frame totals.
  SampleStats total(Phase p) const;
  std::size_t frames(Phase p) const;

 private:
  /// Per phase (idle, contact): each stage's times, then the totals.
  static constexpr std::size_t kColumns = kStageCount + 1;
  SampleStats column(std::size_t c, Phase p) const;

  std::array<std::array<RunningStats, kColumns>, 2> columns_;
};

/// Plain-text table in the layout of the paper's Table 3: an Idle block and a Contact block, each
/// headed by its frame count, with Mean, Med, Std, P95 and P99 in ms for every stage that took time
/// in any frame, then the total.
std::string latencyTable(const LatencyRecorder& recorder);

/// CSV with header phase,stage,frames,mean_ms,median_ms,std_ms,p95_ms,p99_ms,min_ms,max_ms: one row
/// per stage and one for the total ("total"), for the phases idle, contact and all. `frames` is the
/// count of samples behind the row; statistics of no samples are written as nan.
std::string latencyCsv(const LatencyRecorder& recorder);

}  // namespace vrd
