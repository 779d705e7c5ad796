// The kinematic hand: straight when open, curling into the palm as it closes, rigid with the wrist,
// and finite whatever the glove sends.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "vrdeform/interact/hand.h"

namespace vrd {
namespace {

constexpr Finger kAll[] = {Finger::Thumb, Finger::Index, Finger::Middle, Finger::Ring, Finger::Little};

float length(const FingerGeometry& f) { return f.phalanx[0] + f.phalanx[1] + f.phalanx[2]; }

TEST(Hand, OpenFingersAreStraight) {
  const HandGeometry hand = HandGeometry::average();
  for (Finger finger : kAll) {
    const FingerGeometry& f = hand.fingers[int(finger)];
    const Vec3 tip = fingertipPosition(hand, HandPose{}, finger);
    EXPECT_LT((tip - (f.knuckle + length(f) * f.direction)).norm(), 1e-6f);
  }
}

TEST(Hand, ClosingCurlsEachFingerTowardsThePalmWithinReach) {
  const HandGeometry hand = HandGeometry::average();
  for (Finger finger : kAll) {
    const FingerGeometry& f = hand.fingers[int(finger)];
    float previousReach = length(f) + 1.0f;
    for (float c = 0.0f; c <= 1.0f; c += 0.125f) {
      HandPose pose;
      pose.closure[int(finger)] = c;
      const float reach = (fingertipPosition(hand, pose, finger) - f.knuckle).norm();
      EXPECT_LE(reach, length(f) + 1e-6f);  // the chain cannot stretch
      EXPECT_LT(reach, previousReach);      // and folds up as it closes
      previousReach = reach;
    }
    if (finger != Finger::Thumb) {  // in a fist the tip comes back over the palm, on its side
      HandPose fist;
      fist.closure[int(finger)] = 1.0f;
      const Vec3 tip = fingertipPosition(hand, fist, finger);
      EXPECT_GT(tip.z(), 0.005f);
      EXPECT_LT(tip.x(), f.knuckle.x());
    }
  }
}

TEST(Hand, PinchBringsThumbAndIndexTogether) {
  const HandGeometry hand = HandGeometry::average();
  HandPose open, pinch;
  pinch.closure[int(Finger::Thumb)] = pinch.closure[int(Finger::Index)] = 0.6f;
  auto gap = [&](const HandPose& p) {
    return (fingertipPosition(hand, p, Finger::Thumb) - fingertipPosition(hand, p, Finger::Index)).norm();
  };
  EXPECT_LT(gap(pinch), 0.6f * gap(open));
}

TEST(Hand, WristPoseMovesTheHandRigidly) {
  const HandGeometry hand = HandGeometry::average();
  HandPose local, moved;
  local.closure = moved.closure = {0.3f, 0.5f, 0.2f, 0.9f, 0.1f};
  moved.wrist = Eigen::Translation3f(0.1f, -0.2f, 1.0f) * Eigen::AngleAxisf(0.7f, Vec3(1, 2, 3).normalized());
  for (Finger finger : kAll)
    EXPECT_LT((fingertipPosition(hand, moved, finger) - moved.wrist * fingertipPosition(hand, local, finger)).norm(),
              1e-6f);
}

TEST(Hand, GloveGarbageGivesFiniteFingertips) {
  const HandGeometry hand = HandGeometry::average();
  HandPose pose;
  pose.closure = {std::numeric_limits<float>::quiet_NaN(), -5.0f, 7.0f, std::numeric_limits<float>::infinity(), 0.5f};
  HandPose clamped;
  clamped.closure = {0.0f, 0.0f, 1.0f, 0.0f, 0.5f};
  for (Finger finger : kAll) {
    const Vec3 tip = fingertipPosition(hand, pose, finger);
    EXPECT_TRUE(isFinite(tip));
    EXPECT_EQ(tip, fingertipPosition(hand, clamped, finger));
  }
}

}  // namespace
}  // namespace vrd
