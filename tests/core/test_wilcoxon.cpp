// The Wilcoxon signed-rank test against values worked out independently: a textbook example with
// ties (normal approximation), the exact distribution against an enumeration of every sign
// pattern and against the tables' classic values.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "test_support.h"
#include "vrdeform/metrics/wilcoxon.h"

namespace vrd {
namespace {

TEST(Wilcoxon, TiedExampleUsesTheNormalApproximationWithTheTieCorrection) {
  // Wikipedia's worked example: ten pairs, one zero difference (dropped), |d| = 5 twice (ranks 1.5).
  const std::vector<double> x{125, 115, 130, 140, 140, 115, 140, 125, 140, 135};
  const std::vector<double> y{110, 122, 125, 120, 140, 124, 123, 137, 135, 145};
  const WilcoxonResult r = wilcoxonSignedRank(x, y);
  EXPECT_EQ(r.n, 9u);
  EXPECT_EQ(r.wPlus, 27.0);
  EXPECT_EQ(r.wMinus, 18.0);
  EXPECT_FALSE(r.exact);
  // sd^2 = 9 * 10 * 19 / 24 - (2^3 - 2) / 48; z = (27 - 22.5) / sd; p = erfc(z / sqrt 2), by hand.
  EXPECT_NEAR(r.z, 0.533582250055877, 1e-12);
  EXPECT_NEAR(r.p, 0.5936305914425295, 1e-9);
  EXPECT_NEAR(r.effectSize, 0.533582250055877 / 3.0, 1e-12);

  const WilcoxonResult swapped = wilcoxonSignedRank(y, x);  // the other way round: the same p
  EXPECT_EQ(swapped.wPlus, 18.0);
  EXPECT_NEAR(swapped.p, r.p, 1e-15);
  EXPECT_NEAR(swapped.z, -r.z, 1e-15);
}

TEST(Wilcoxon, ExactPValuesMatchTheTables) {
  // All n differences positive: W+ takes its largest value, once in 2^n sign patterns.
  for (int n : {5, 6, 10}) {
    std::vector<double> a, b(std::size_t(n), 0.0);
    for (int i = 1; i <= n; ++i) a.push_back(i);
    const WilcoxonResult r = wilcoxonSignedRank(a, b);
    EXPECT_TRUE(r.exact);
    EXPECT_EQ(r.wPlus, n * (n + 1) / 2.0);
    EXPECT_DOUBLE_EQ(r.p, 2.0 / std::ldexp(1.0, n)) << n;  // n = 5: 0.0625, the smallest there is
  }
  // n = 10: W = 8 is the tables' two-sided 5% critical value (p 0.0488), 9 is not (0.0645).
  std::vector<double> a, b(10, 0.0);
  for (int i = 1; i <= 10; ++i) a.push_back(i == 8 ? -i : i);  // W- = 8
  EXPECT_NEAR(wilcoxonSignedRank(a, b).p, 0.048828125, 1e-15);
  a = {1, 2, 3, 4, 5, 6, 7, 8, -9, 10};  // W- = 9
  EXPECT_NEAR(wilcoxonSignedRank(a, b).p, 0.064453125, 1e-15);
}

TEST(Wilcoxon, ExactDistributionMatchesEnumeratingEverySignPattern) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> magnitude(0.1, 10.0);
  const int n = 12;
  std::vector<double> size(n);
  for (double& m : size) m = magnitude(random);  // distinct: no ties
  for (unsigned pattern : {0u, 1u, 0x0f0u, 0x5a5u, 0xabcu, 0xfffu}) {
    std::vector<double> a(n), b(n, 0.0);
    for (int i = 0; i < n; ++i) a[std::size_t(i)] = (pattern >> i & 1u) ? size[std::size_t(i)] : -size[std::size_t(i)];
    const WilcoxonResult r = wilcoxonSignedRank(a, b);
    ASSERT_TRUE(r.exact);
    // The enumeration: W+ of every sign pattern over ranks 1..n.
    double below = 0, above = 0;
    for (unsigned s = 0; s < (1u << n); ++s) {
      double w = 0;
      for (int k = 0; k < n; ++k) w += (s >> k & 1u) ? k + 1 : 0;
      below += w <= r.wPlus, above += w >= r.wPlus;
    }
    const double p = std::min(1.0, 2.0 * std::min(below, above) / double(1u << n));
    EXPECT_DOUBLE_EQ(r.p, p) << "pattern " << pattern;
  }
}

TEST(Wilcoxon, NoDifferenceAndBadInput) {
  const std::vector<double> same{3, 4, 5};
  const WilcoxonResult r = wilcoxonSignedRank(same, same);
  EXPECT_EQ(r.n, 0u);
  EXPECT_EQ(r.p, 1.0);
  const std::vector<double> two{1, 2}, nan{1, std::nan("")};
  EXPECT_NE(testing::errorOf([&] { wilcoxonSignedRank(same, two); }).find("paired"), std::string::npos);
  EXPECT_NE(testing::errorOf([&] { wilcoxonSignedRank(two, nan); }).find("pair 2"), std::string::npos);
}

}  // namespace
}  // namespace vrd
