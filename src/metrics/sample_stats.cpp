#include "vrdeform/metrics/sample_stats.h"

#include <algorithm>
#include <cmath>

namespace vrd {

double percentileOfSorted(std::span<const double> x, double p) {
  const double h = double(x.size() - 1) * p;
  const std::size_t lo = std::size_t(h);
  if (lo + 1 >= x.size()) return x.back();
  return x[lo] + (h - double(lo)) * (x[lo + 1] - x[lo]);
}

namespace {

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
  s.median = percentileOfSorted(x, 0.50);
  s.p95 = percentileOfSorted(x, 0.95);
  s.p99 = percentileOfSorted(x, 0.99);
  s.min = x.front();
  s.max = x.back();
  return s;
}

}  // namespace

SampleStats summarise(std::span<const double> samples) {
  std::vector<double> x(samples.begin(), samples.end());
  return summariseInPlace(x);
}

RunningStats::RunningStats() : buckets_(kBuckets, 0) { samples_.reserve(kExactSamples); }

std::size_t RunningStats::bucketOf(double sample) {
  if (!(sample >= kLowest)) return 0;
  const double b = std::floor(std::log2(sample / kLowest) * kBucketsPerOctave);
  return std::size_t(std::min(b + 1.0, double(kBuckets - 1)));
}

void RunningStats::toHistogram() {
  for (double x : samples_) ++buckets_[bucketOf(x)];
  samples_.clear();
  histogram_ = true;
}

void RunningStats::add(double sample) {
  if (!std::isfinite(sample)) return;
  ++count_;
  const double delta = sample - mean_;
  mean_ += delta / double(count_);
  squares_ += delta * (sample - mean_);
  min_ = count_ == 1 ? sample : std::min(min_, sample);
  max_ = count_ == 1 ? sample : std::max(max_, sample);
  if (histogram_) {
    ++buckets_[bucketOf(sample)];
  } else {
    samples_.push_back(sample);
    if (samples_.size() == kExactSamples) toHistogram();
  }
}

void RunningStats::merge(const RunningStats& other) {
  if (other.count_ == 0) return;
  if (count_ == 0) {  // keeps this one's storage, so that add() still never allocates
    count_ = other.count_;
    mean_ = other.mean_;
    squares_ = other.squares_;
    min_ = other.min_;
    max_ = other.max_;
    histogram_ = other.histogram_;
    samples_.assign(other.samples_.begin(), other.samples_.end());
    buckets_ = other.buckets_;
    return;
  }
  // Chan et al.'s pairwise update of the mean and the sum of squared deviations.
  const double n = double(count_), m = double(other.count_), delta = other.mean_ - mean_;
  mean_ += delta * m / (n + m);
  squares_ += other.squares_ + delta * delta * n * m / (n + m);
  count_ += other.count_;
  min_ = std::min(min_, other.min_);
  max_ = std::max(max_, other.max_);
  if (!histogram_ && !other.histogram_ && samples_.size() + other.samples_.size() < kExactSamples) {
    samples_.insert(samples_.end(), other.samples_.begin(), other.samples_.end());
    return;
  }
  if (!histogram_) toHistogram();
  for (double x : other.samples_) ++buckets_[bucketOf(x)];
  for (std::size_t b = 0; b < kBuckets; ++b) buckets_[b] += other.buckets_[b];
}

double RunningStats::percentile(double p) const {
  // The rank summarise() reads at (type 7), found in the buckets' running count and placed within
  // its bucket as if the bucket's samples were spread evenly over it on a log scale.
  const double h = double(count_ - 1) * p;
  double before = 0.0;
  for (std::size_t b = 0; b < kBuckets; ++b) {
    const double n = double(buckets_[b]);
    if (n == 0.0 || before + n <= h) {
      before += n;
      continue;
    }
    if (b == 0) return min_;
    if (b == kBuckets - 1) return max_;
    const double f = (double(b - 1) + (h - before + 0.5) / n) / kBucketsPerOctave;
    return std::clamp(kLowest * std::exp2(f), min_, max_);
  }
  return max_;
}

SampleStats RunningStats::stats() const {
  if (!histogram_) return summarise(samples_);
  SampleStats s;
  s.count = count_;
  s.mean = mean_;
  s.stddev = std::sqrt(squares_ / double(count_));
  s.min = min_;
  s.max = max_;
  s.median = percentile(0.50);
  s.p95 = percentile(0.95);
  s.p99 = percentile(0.99);
  return s;
}

}  // namespace vrd
