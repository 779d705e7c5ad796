// Signal quality of a press (metrics/signal_quality.h) on signals whose figures are known.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "vrdeform/metrics/signal_quality.h"

namespace vrd {
namespace {

// A press: 10 steps in the air, 60 loading to 10 mm, 60 holding, 60 releasing, 20 in the air.
struct Press {
  std::vector<double> depth;
  std::size_t holdBegin = 70, holdEnd = 130;
  Press() {
    for (int i = 0; i < 10; ++i) depth.push_back(-0.001);
    for (int i = 1; i <= 60; ++i) depth.push_back(0.01 * i / 60.0);
    for (int i = 0; i < 60; ++i) depth.push_back(0.01);
    for (int i = 1; i <= 60; ++i) depth.push_back(0.01 * (1.0 - i / 60.0));
    for (int i = 0; i < 20; ++i) depth.push_back(-0.001);
  }
  std::vector<double> linearForce(double stiffness, int delay = 0) const {
    std::vector<double> f(depth.size(), 0.0);
    for (std::size_t i = 0; i < f.size(); ++i)
      if (i >= std::size_t(delay)) f[i] = stiffness * std::max(0.0, depth[i - std::size_t(delay)]);
    return f;
  }
};

TEST(SignalQuality, ACleanPressIsOneRiseAndFall) {
  const Press p;
  const auto f = p.linearForce(50.0);
  const SignalQuality q = signalQuality(p.depth, f, p.holdBegin, p.holdEnd);
  EXPECT_NEAR(q.roughness, 1.0, 1e-12);
  EXPECT_NEAR(q.loadingSpearman, 1.0, 1e-12);
  EXPECT_NEAR(q.holdNoise, 0.0, 1e-12);
  EXPECT_EQ(q.lagSteps, 0);
  EXPECT_NEAR(q.peak, 0.5, 1e-12);
}

TEST(SignalQuality, ADelayedForceShowsItsLag) {
  const Press p;
  for (int delay : {1, 3, 7}) EXPECT_EQ(signalQuality(p.depth, p.linearForce(50.0, delay), 70, 130).lagSteps, delay);
}

TEST(SignalQuality, AWobbleAddsRoughnessAndNoise) {
  const Press p;
  auto f = p.linearForce(50.0);
  // +-10% of the peak at a period of 20 steps while in contact: steeper than the loading ramp, so
  // the force dips while the depth rises. The hold's three periods alone add 3 x 4 x 0.05 = 0.6 of
  // variation to the clean rise and fall's 2 x 0.5, over 2 x the peak of at most 0.55.
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f[i] > 0) f[i] += 0.05 * std::sin(2 * std::numbers::pi * double(i) / 20.0);
  const SignalQuality q = signalQuality(p.depth, f, p.holdBegin, p.holdEnd);
  EXPECT_GT(q.roughness, (1.0 + 0.6) / 1.1);
  // A sine of amplitude 0.05 over whole periods on a mean of 0.5: sd 0.05 / sqrt(2), noise 7.1%.
  EXPECT_NEAR(q.holdNoise, 0.05 / std::sqrt(2.0) / 0.5, 1e-9);
  EXPECT_LT(q.loadingSpearman, 0.99);
}

TEST(SignalQuality, SpearmanCountsOrderNotShape) {
  const std::vector<double> x{1, 2, 3, 4, 5}, cubic{1, 8, 27, 64, 125}, reversed{5, 4, 3, 2, 1}, ties{1, 1, 2, 2, 3};
  EXPECT_DOUBLE_EQ(spearman(x, cubic), 1.0);
  EXPECT_DOUBLE_EQ(spearman(x, reversed), -1.0);
  EXPECT_NEAR(spearman(x, ties), 0.9487, 1e-4);  // ranks 0.5 0.5 2.5 2.5 4 against 0..4
  EXPECT_TRUE(std::isnan(spearman(x, std::vector<double>{2, 2, 2, 2, 2})));
}

}  // namespace
}  // namespace vrd
