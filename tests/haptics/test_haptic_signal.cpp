// The paper's haptic signal (eqs. 40-44) on hand-made multipliers with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "vrdeform/haptics/haptic_signal.h"

namespace vrd {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(HapticSignal, ContactIsTheMeanMagnitudeOverTau) {
  EXPECT_EQ(normalisedContact(0.0f, 0, 1.0f), 0.0f);
  EXPECT_EQ(normalisedContact(5.0f, 0, 1.0f), 0.0f);        // empty N(r): no contact term
  EXPECT_FLOAT_EQ(normalisedContact(4.0f, 2, 4.0f), 0.5f);  // (1 + 3) / (2 * 4)
  EXPECT_FLOAT_EQ(normalisedContact(4.0f, 2, 1.0f), 1.0f);  // clipped
  EXPECT_EQ(normalisedContact(kNaN, 2, 1.0f), 0.0f);
}

TEST(HapticSignal, TetSignalWeighsClippedVolumeAndStrain) {
  HapticSignalSettings s;
  s.betaVolume = 0.25f;
  s.betaStrain = 0.75f;
  s.tauVolume = 2.0f;
  s.tauStrain = 1.0f;
  const StrainLambda strain{0.3f, 0.0f, 0.4f, 0.0f, 0.0f, 0.0f};  // norm 0.5
  EXPECT_FLOAT_EQ(tetSignal(-1.0f, strain, s), 0.25f * 0.5f + 0.75f * 0.5f);
  const StrainLambda huge{10.0f, 0, 0, 0, 0, 0};
  EXPECT_FLOAT_EQ(tetSignal(-100.0f, huge, s), 1.0f);  // both clipped to 1
  EXPECT_FLOAT_EQ(tetSignal(kNaN, strain, s), 0.75f * 0.5f);
}

TEST(HapticSignal, ABodysTetSignalsAreEachTetsTetSignal) {
  HapticSignalSettings s;
  s.tauVolume = 0.5f;
  s.tauStrain = 2.0f;
  constexpr std::size_t n = 37;  // not a multiple of any lane width
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::vector<float> volume(n), strain(kStrainComponents * n), out(n);
  for (float& v : volume) v = u(rng);
  for (float& v : strain) v = u(rng);
  volume[5] = kNaN, strain[2 * n + 9] = kNaN;
  const auto strainOf = [&](std::size_t j) {
    StrainLambda l;
    for (int k = 0; k < kStrainComponents; ++k) l[k] = strain[std::size_t(k) * n + j];
    return l;
  };
  tetSignals(volume, strain, s, out);
  for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(out[j], tetSignal(volume[j], strainOf(j), s)) << j;
  tetSignals({}, strain, s, out);  // a body without volume constraints
  for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(out[j], tetSignal(0.0f, strainOf(j), s)) << j;
  tetSignals(volume, {}, s, out);  // nor strain constraints
  for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(out[j], tetSignal(volume[j], StrainLambda{}, s)) << j;
}

TetSignals tetsAt(const std::vector<Vec3>& centroids, const std::vector<float>& f) {
  TetSignals t;
  t.resize(centroids.size());
  for (std::size_t j = 0; j < centroids.size(); ++j) t.setCentroid(j, centroids[j]), t.f[j] = f[j];
  return t;
}

TEST(HapticSignal, VolumeStrainAverageFavoursTetsNearTheGraspCentre) {
  const TetSignals two = tetsAt({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {1.0f, 0.0f});  // f = 1 at the centre, 0 1 m away
  // w = 1/(0 + 1e-3) = 1000 and 1/(1 + 1e-3): F_VS = 1000 / (1000 + 0.999).
  EXPECT_NEAR(volumeStrainSignal(two, Vec3::Zero(), 1e-3f), 1000.0 / (1000.0 + 1.0 / 1.001), 1e-6);
  // Seen from halfway, both weigh the same: the plain mean.
  EXPECT_NEAR(volumeStrainSignal(two, Vec3(0.5f, 0, 0), 1e-3f), 0.5, 1e-6);
  EXPECT_EQ(volumeStrainSignal(TetSignals{}, Vec3::Zero(), 1e-3f), 0.0f);
}

TEST(HapticSignal, VolumeStrainAverageOfABigBodyKeepsDoublePrecision) {
  // 1,000,003 tets (lanes, blocks and a tail) against the sum in double: float lanes summed into
  // doubles every few hundred tets stay within a few float roundings of it, where float lanes
  // summed throughout are off by 5.5e-6 (and one float sum by 5e-5).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f), unit(0.0f, 1.0f);
  std::vector<Vec3> centroids(1000003);
  std::vector<float> f(centroids.size());
  for (std::size_t j = 0; j < centroids.size(); ++j) centroids[j] = Vec3(u(rng), u(rng), u(rng)), f[j] = unit(rng);
  const Vec3 centre(0.1f, 0.2f, -0.05f);
  double weighted = 0.0, weights = 0.0;
  for (std::size_t j = 0; j < centroids.size(); ++j) {
    const double w = 1.0 / ((centroids[j] - centre).cast<double>().norm() + 1e-3);
    weighted += w * f[j], weights += w;
  }
  EXPECT_NEAR(volumeStrainSignal(tetsAt(centroids, f), centre, 1e-3f), weighted / weights, 1e-6);
}

TEST(HapticSignal, RawForceFollowsTheThreeCasesOfEq43) {
  HapticSignalSettings s;
  s.betaContact = 0.6f;
  EXPECT_EQ(rawHapticForce(false, 0, 0.9f, 0.7f, s), 0.0f);  // no contact, no grasp: no force
  EXPECT_FLOAT_EQ(rawHapticForce(false, 3, 0.9f, 0.5f, s), 0.6f * 0.9f + 0.4f * 0.5f);
  EXPECT_FLOAT_EQ(rawHapticForce(true, 0, 0.9f, 0.7f, s), 0.7f);  // grasping ignores contact
  EXPECT_EQ(rawHapticForce(false, 2, kNaN, kNaN, s), 0.0f);
}

TEST(HapticSignal, SmoothingIsAFirstOrderLagThatNeverLeavesTheUnitInterval) {
  const float alpha = 0.2f;
  float out = 0.0f;
  for (int n = 1; n <= 10; ++n) {
    out = smoothHapticForce(out, 1.0f, alpha);
    EXPECT_NEAR(out, 1.0 - std::pow(1.0 - alpha, n), 1e-6);  // step response
  }
  for (int n = 0; n < 200; ++n) out = smoothHapticForce(out, kNaN, alpha);  // a NaN source reads as 0
  EXPECT_GE(out, 0.0f);
  EXPECT_LT(out, 1e-6f);
  EXPECT_EQ(smoothHapticForce(0.5f, 7.0f, 1.0f), 1.0f);
  EXPECT_EQ(smoothHapticForce(kNaN, 0.5f, 0.5f), 0.25f);
}

TEST(HapticSignal, ChangeLimitCapsEachStepButReachesTheTarget) {
  EXPECT_FLOAT_EQ(limitChange(0.0f, 1.0f, 0.25f), 0.25f);
  EXPECT_FLOAT_EQ(limitChange(0.5f, 0.0f, 0.25f), 0.25f);
  EXPECT_FLOAT_EQ(limitChange(0.5f, 0.6f, 0.25f), 0.6f);
  float out = 0.0f;
  for (int n = 0; n < 4; ++n) out = limitChange(out, 1.0f, 0.25f);
  EXPECT_FLOAT_EQ(out, 1.0f);
}

}  // namespace
}  // namespace vrd
