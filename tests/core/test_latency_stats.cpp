// Latency statistics (paper Table 3) on sample sets whose statistics are known by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
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

TEST(LatencyRecorder, SplitsIdleAndContactFrames) {
  LatencyRecorder r;
  r.reserve(8);
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
