#pragma once
// Latency statistics per stage, for frames without and with contact (paper Table 3).

#include <array>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "vrdeform/metrics/stage_times.h"

namespace vrd {

/// Summary of a set of samples. With no usable samples (as constructed), count is 0 and every value NaN.
struct SampleStats {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::size_t count = 0;  ///< samples used (non-finite samples are left out)
  double mean = kNaN;     ///< arithmetic mean
  double median = kNaN;   ///< 50th percentile
  double stddev = kNaN;   ///< population standard deviation (divides by count)
  double p95 = kNaN;      ///< 95th percentile
  double p99 = kNaN;      ///< 99th percentile
  double min = kNaN;      ///< smallest sample
  double max = kNaN;      ///< largest sample
};

/// Summarises `samples`, leaving out NaN (and infinities: no timing is infinite, and one would
/// poison the mean and deviation). Percentiles interpolate linearly between closest ranks
/// (Hyndman-Fan type 7, numpy's default): with the n samples sorted as x[0..n-1], the p-th
/// percentile is x[h] read at h = (n - 1) p, interpolating between x[floor h] and x[floor h + 1].
/// So 1..100 gives median 50.5, P95 95.05, P99 99.01.
SampleStats summarise(std::span<const double> samples);

/// Which frames a statistic covers.
enum class Phase {
  Idle,     ///< frames without contact
  Contact,  ///< frames with contact
  All       ///< both
};

/// Per-stage times of many frames, kept apart for idle and contact frames. Adding a frame does not
/// allocate while the frames fit what reserve() asked for.
class LatencyRecorder {
 public:
  /// Room for `frames` frames in each of the idle and contact series.
  void reserve(std::size_t frames);
  /// Records one frame's per-stage times and their total (t.totalMs()).
  void add(const StageTimes& t, bool contact);

  SampleStats stage(Stage s, Phase p) const;
  /// Statistics of the frame totals.
  SampleStats total(Phase p) const;
  std::size_t frames(Phase p) const;

 private:
  /// One row per frame: kStageCount stage times, then the total.
  static constexpr std::size_t kColumns = kStageCount + 1;
  SampleStats column(std::size_t c, Phase p) const;

  std::array<std::vector<double>, 2> rows_;  ///< idle, contact; row-major, kColumns per frame
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
