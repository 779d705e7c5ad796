// The paper's haptic signal (eqs. 40-44) on hand-made multipliers with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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

TEST(HapticSignal, VolumeStrainAverageFavoursTetsNearTheGraspCentre) {
  const std::vector<Vec3> centroids{Vec3(0, 0, 0), Vec3(1, 0, 0)};
  const std::vector<float> f{1.0f, 0.0f};  // f = 1 at the centre, 0 one metre away
  // w = 1/(0 + 1e-3) = 1000 and 1/(1 + 1e-3): F_VS = 1000 / (1000 + 0.999).
  EXPECT_NEAR(volumeStrainSignal(centroids, f, Vec3::Zero(), 1e-3f), 1000.0 / (1000.0 + 1.0 / 1.001), 1e-6);
  // Seen from halfway, both weigh the same: the plain mean.
  EXPECT_NEAR(volumeStrainSignal(centroids, f, Vec3(0.5f, 0, 0), 1e-3f), 0.5, 1e-6);
  EXPECT_EQ(volumeStrainSignal({}, {}, Vec3::Zero(), 1e-3f), 0.0f);
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
