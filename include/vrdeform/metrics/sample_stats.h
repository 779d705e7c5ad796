#pragma once
// Summary statistics of samples: of a set at hand, or of a stream of any length in fixed memory
// (the step times of a session that runs for hours: Table 3's rows, a loop's step P99).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

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

/// The p-th percentile (p in [0, 1]) of sorted, non-empty samples, as summarise() reads them (type 7).
double percentileOfSorted(std::span<const double> sorted, double p);

/// Exactly summarise() of the samples while fewer than kExactSamples were added; from then on
/// count, mean, deviation, minimum and maximum from running sums (Welford's), and percentiles from
/// a histogram of kBucketsPerOctave buckets per factor of two over [kLowest, kHighest], which puts
/// a percentile within one bucket (2^(1/64) - 1 = 1.1%) of its exact value for samples in range. Samples
/// below kLowest (zero: a stage that did not run) share one bucket, as do those above kHighest;
/// percentiles never leave [min, max]. Non-finite samples are left out, as by summarise().
/// Construction allocates everything: add() never does.
class RunningStats {
 public:
  static constexpr std::size_t kExactSamples = 2048;
  static constexpr int kBucketsPerOctave = 64;
  static constexpr int kOctaves = 42;
  static constexpr double kLowest = 1e-6;  ///< kHighest = kLowest 2^kOctaves, about 4.4e6

  RunningStats();

  void add(double sample);
  /// Adds everything `other` was given: stats() is then that of both streams together.
  void merge(const RunningStats& other);
  std::size_t count() const { return count_; }
  SampleStats stats() const;

 private:
  static constexpr std::size_t kBuckets = 1 + std::size_t(kOctaves) * kBucketsPerOctave + 1;
  static std::size_t bucketOf(double sample);
  void toHistogram();
  double percentile(double p) const;

  std::size_t count_ = 0;
  double mean_ = 0.0, squares_ = 0.0;  // Welford: running mean and sum of squared deviations
  double min_ = 0.0, max_ = 0.0;
  bool histogram_ = false;              // samples_ folded into buckets_, which count from then on
  std::vector<double> samples_;         // while !histogram_
  std::vector<std::uint64_t> buckets_;  // kBuckets: below kLowest, the octaves' buckets, above
};

}  // namespace vrd
