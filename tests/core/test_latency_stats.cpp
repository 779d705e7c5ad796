// Latency statistics (paper Table 3) on sample sets whose statistics are known by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "vrdeform/metrics/latency_stats.h"

namespace vrd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<double> oneTo(int n) {
  std::vector<double> x(std::size_t(n), 0.0);
  std::iota(x.begin(), x.end(), 1.0);
  return x;
}

TEST(LatencyStats, OneToHundredMatchesTheType7Definition) {
  std::vector<double> x = oneTo(100);
  std::reverse(x.begin(), x.end());  // order must not matter
  const SampleStats s = summarise(x);
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.median, 50.5);  // h = 99 * 0.5 = 49.5: halfway between 50 and 51
  EXPECT_NEAR(s.p95, 95.05, 1e-12);  // h = 94.05: 95 + 0.05 * (96 - 95)
  EXPECT_NEAR(s.p99, 99.01, 1e-12);  // h = 98.01
  EXPECT_NEAR(s.stddev, std::sqrt((100.0 * 100.0 - 1.0) / 12.0), 1e-12);  // population std of 1..n
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 100.0);
}

TEST(LatencyStats, SmallSetsByHand) {
  const SampleStats four = summarise(std::vector<double>{4.0, 1.0, 3.0, 2.0});
  EXPECT_DOUBLE_EQ(four.median, 2.5);
  EXPECT_NEAR(four.p95, 3.85, 1e-12);  // h = 3 * 0.95 = 2.85: 3 + 0.85
  EXPECT_NEAR(four.p99, 3.97, 1e-12);
  EXPECT_NEAR(four.stddev, std::sqrt(1.25), 1e-12);  // sqrt((n^2 - 1) / 12), n = 4
  const SampleStats odd = summarise(std::vector<double>{10.0, 0.0, 5.0});
  EXPECT_DOUBLE_EQ(odd.median, 5.0);
  EXPECT_NEAR(odd.stddev, std::sqrt(50.0 / 3.0), 1e-12);
}

TEST(LatencyStats, SingleSampleIsEveryStatistic) {
  const SampleStats s = summarise(std::vector<double>{2.5});
  EXPECT_EQ(s.count, 1u);
  for (double v : {s.mean, s.median, s.p95, s.p99, s.min, s.max}) EXPECT_EQ(v, 2.5);
  EXPECT_EQ(s.stddev, 0.0);
}

TEST(LatencyStats, NonFiniteSamplesAreLeftOutAndNotCounted) {
  const double inf = std::numeric_limits<double>::infinity();
  const SampleStats s = summarise(std::vector<double>{kNaN, 1.0, kNaN, 3.0, inf});
  EXPECT_EQ(s.count, 2u);
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_DOUBLE_EQ(s.median, 2.0);
  EXPECT_DOUBLE_EQ(s.stddev, 1.0);
  EXPECT_EQ(s.max, 3.0);
}

TEST(LatencyStats, EmptyInputHasCountZeroAndNaNValues) {
  for (const SampleStats& s : {summarise({}), summarise(std::vector<double>{kNaN})}) {
    EXPECT_EQ(s.count, 0u);
    for (double v : {s.mean, s.median, s.stddev, s.p95, s.p99, s.min, s.max}) EXPECT_TRUE(std::isnan(v));
  }
}

/// Frames whose predict stage takes `predict` ms and whose force stage takes `force` ms.
StageTimes frame(double predict, double force) {
  StageTimes t;
  t[Stage::Predict] = predict;
  t[Stage::Force] = force;
  return t;
}

// Step-time-like samples: log-normal around 0.3 ms, one in fifty a spike near 5 ms (so that P99 is
// among the spikes, not in the gap below them) and one in fifty a stage that did not run (0).
std::vector<double> stepTimes(std::size_t n, unsigned seed) {
  std::mt19937_64 random(seed);
  std::lognormal_distribution<double> typical(std::log(0.3), 0.4), spike(std::log(5.0), 0.2);
  std::uniform_int_distribution<int> kind(0, 99);
  std::vector<double> x(n);
  for (double& v : x) {
    const int k = kind(random);
    v = k <= 1 ? spike(random) : k <= 3 ? 0.0 : typical(random);
  }
  return x;
}

RunningStats streamOf(std::span<const double> x) {
  RunningStats r;
  for (double v : x) r.add(v);
  return r;
}

void expectSame(const SampleStats& a, const SampleStats& b) {
  EXPECT_EQ(a.count, b.count);
  for (auto m : {&SampleStats::mean, &SampleStats::median, &SampleStats::stddev, &SampleStats::p95, &SampleStats::p99,
                 &SampleStats::min, &SampleStats::max})
    EXPECT_DOUBLE_EQ(a.*m, b.*m);
}

TEST(RunningStats, IsSummariseWhileFewerThanItsExactSamples) {
  const std::vector<double> x = stepTimes(RunningStats::kExactSamples - 1, 1);
  expectSame(streamOf(x).stats(), summarise(x));
  std::vector<double> withNaN = x;
  withNaN.insert(withNaN.begin() + 10, {kNaN, std::numeric_limits<double>::infinity()});
  expectSame(streamOf(withNaN).stats(), summarise(x));  // left out, as by summarise()
  EXPECT_EQ(RunningStats().stats().count, 0u);
  EXPECT_TRUE(std::isnan(RunningStats().stats().p99));
}

TEST(RunningStats, AMillionSamplesKeepEveryPercentileWithinABucket) {
  const std::vector<double> x = stepTimes(1'000'000, 2);
  const SampleStats streamed = streamOf(x).stats(), exact = summarise(x);
  EXPECT_EQ(streamed.count, exact.count);
  EXPECT_EQ(streamed.min, exact.min);
  EXPECT_EQ(streamed.max, exact.max);
  EXPECT_NEAR(streamed.mean, exact.mean, 1e-9 * exact.mean);  // running sums: rounding only
  EXPECT_NEAR(streamed.stddev, exact.stddev, 1e-9 * exact.stddev);
  // A percentile lies in the bucket of its rank: at most one bucket's width, 2^(1/64) - 1, away.
  const double width = std::exp2(1.0 / RunningStats::kBucketsPerOctave) - 1.0;
  for (auto m : {&SampleStats::median, &SampleStats::p95, &SampleStats::p99}) {
    EXPECT_NEAR(streamed.*m, exact.*m, width * exact.*m);
    EXPECT_NE(streamed.*m, exact.*m);  // from the histogram, not the samples
  }
}

TEST(RunningStats, AStageThatNeverRanStaysZeroAndOutliersStayInRange) {
  RunningStats zeros, wide;
  for (int i = 0; i < 10'000; ++i) {
    zeros.add(0.0);
    wide.add(i % 2 ? 1e-9 : 1e9);  // below and above the histogram's range
  }
  EXPECT_EQ(zeros.stats().median, 0.0);
  EXPECT_EQ(zeros.stats().p99, 0.0);
  EXPECT_EQ(wide.stats().median, 1e-9);
  EXPECT_EQ(wide.stats().p99, 1e9);
}

TEST(RunningStats, MergedStreamsSummariseAsOne) {
  const std::vector<double> x = stepTimes(10'000, 3);
  const std::span<const double> all(x);
  // Both still exact: exactly summarise() of both.
  RunningStats a = streamOf(all.first(100));
  a.merge(streamOf(all.subspan(100, 200)));
  expectSame(a.stats(), summarise(all.first(300)));
  // One exact and one histogram: the histogram of the one stream.
  RunningStats b = streamOf(all.first(500)), whole = streamOf(all);
  b.merge(streamOf(all.subspan(500)));
  const SampleStats merged = b.stats(), one = whole.stats();
  EXPECT_EQ(merged.count, one.count);
  EXPECT_EQ(merged.median, one.median);
  EXPECT_EQ(merged.p99, one.p99);
  EXPECT_NEAR(merged.mean, one.mean, 1e-12 * one.mean);
  EXPECT_NEAR(merged.stddev, one.stddev, 1e-12 * one.stddev);
  RunningStats empty;
  empty.merge(whole);
  expectSame(empty.stats(), one);
}

TEST(LatencyRecorder, KeepsEveryFrameOfALongRunInFixedMemory) {
  // Past the exact samples both phases and their union come from the histograms.
  LatencyRecorder r;
  const std::vector<double> x = stepTimes(100'000, 4);
  for (std::size_t i = 0; i < x.size(); ++i) r.add(frame(x[i], 0.0), i % 4 == 0);
  EXPECT_EQ(r.frames(Phase::Idle), 75'000u);
  EXPECT_EQ(r.frames(Phase::Contact), 25'000u);
  const SampleStats all = r.stage(Stage::Predict, Phase::All), exact = summarise(x);
  EXPECT_EQ(all.count, x.size());
  EXPECT_NEAR(all.p99, exact.p99, 0.011 * exact.p99);
  EXPECT_NEAR(r.total(Phase::All).mean, exact.mean, 1e-9 * exact.mean);
}

TEST(LatencyRecorder, SplitsIdleAndContactFrames) {
  LatencyRecorder r;
  for (int i = 1; i <= 4; ++i) r.add(frame(i, 0.0), false);        // idle predict 1..4
  for (int i = 1; i <= 3; ++i) r.add(frame(10.0 * i, 1.0), true);  // contact predict 10, 20, 30
  EXPECT_EQ(r.frames(Phase::Idle), 4u);
  EXPECT_EQ(r.frames(Phase::Contact), 3u);
  EXPECT_EQ(r.frames(Phase::All), 7u);

  EXPECT_DOUBLE_EQ(r.stage(Stage::Predict, Phase::Idle).mean, 2.5);
  EXPECT_DOUBLE_EQ(r.stage(Stage::Predict, Phase::Contact).median, 20.0);
  EXPECT_DOUBLE_EQ(r.stage(Stage::Predict, Phase::All).max, 30.0);
  EXPECT_EQ(r.stage(Stage::Predict, Phase::All).count, 7u);
  EXPECT_EQ(r.stage(Stage::Force, Phase::Idle).max, 0.0);
  EXPECT_EQ(r.stage(Stage::Force, Phase::Contact).min, 1.0);
  // Totals are per-frame sums: contact frames take 11, 21 and 31 ms.
  EXPECT_DOUBLE_EQ(r.total(Phase::Contact).mean, 21.0);
  EXPECT_DOUBLE_EQ(r.total(Phase::Idle).mean, 2.5);
  EXPECT_EQ(r.total(Phase::All).count, 7u);
}

TEST(LatencyRecorder, EmptyRecorderHasNoFrames) {
  const LatencyRecorder r;
  EXPECT_EQ(r.frames(Phase::All), 0u);
  EXPECT_EQ(r.total(Phase::All).count, 0u);
  EXPECT_TRUE(std::isnan(r.stage(Stage::Volume, Phase::Idle).mean));
}

TEST(LatencyRecorder, TableListsStagesThatTookTimeInBothBlocks) {
  LatencyRecorder r;
  for (int i = 1; i <= 4; ++i) r.add(frame(i, 0.0), false);
  r.add(frame(2.0, 0.5), true);
  const std::string table = latencyTable(r);
  EXPECT_NE(table.find("Idle: 4 frames"), std::string::npos) << table;
  EXPECT_NE(table.find("Contact: 1 frames"), std::string::npos) << table;
  EXPECT_NE(table.find("Mean"), std::string::npos);
  EXPECT_NE(table.find("P99"), std::string::npos);
  // Idle predict: mean 2.5, median 2.5, std sqrt(1.25) = 1.118, P95 3.85, P99 3.97.
  EXPECT_NE(table.find("predict             2.500    2.500    1.118    3.850    3.970"), std::string::npos) << table;
  // Force took time in a contact frame, so it is a row of both blocks; volume never did.
  EXPECT_NE(table.find("force               0.000"), std::string::npos) << table;
  EXPECT_NE(table.find("force               0.500    0.500    0.000"), std::string::npos) << table;
  EXPECT_EQ(table.find("volume"), std::string::npos) << table;
  EXPECT_NE(table.find("total               2.500"), std::string::npos) << table;
  EXPECT_NE(table.find("total               2.500    2.500    0.000"), std::string::npos) << table;

  LatencyRecorder idleOnly;
  idleOnly.add(frame(1.0, 0.0), false);
  EXPECT_NE(latencyTable(idleOnly).find("Contact: no frames"), std::string::npos);
}

TEST(LatencyRecorder, CsvHasEveryStageAndPhase) {
  LatencyRecorder r;
  r.add(frame(1.0, 0.0), false);
  r.add(frame(3.0, 0.0), false);
  const std::string csv = latencyCsv(r);
  EXPECT_EQ(csv.rfind("phase,stage,frames,mean_ms,median_ms,std_ms,p95_ms,p99_ms,min_ms,max_ms\n", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 3 * std::ptrdiff_t(kStageCount + 1));
  EXPECT_NE(csv.find("\nidle,predict,2,2.000000,2.000000,1.000000,2.900000,2.980000,1.000000,3.000000\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("\nall,total,2,2.000000,"), std::string::npos);
  EXPECT_NE(csv.find("\ncontact,shape_matching,0,nan,nan,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\ncontact,total,0,"), std::string::npos);
}

}  // namespace
}  // namespace vrd
