// Scripted pokes and pinch grasps (interact/hand_actions.h): where the fingertips go and when.

#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"
#include "vrdeform/interact/hand_actions.h"

namespace vrd {
namespace {

constexpr float kRadius = 0.01f;

HandAction poke() {
  HandAction a;
  a.target = Vec3(0.1f, 0.2f, 0.3f);
  a.start = 1.0;
  a.approach = 2.0, a.hold = 1.0, a.release = 1.0;
  a.depth = 0.005f;
  return a;
}

HandAction grasp() {
  HandAction a = poke();
  a.kind = ActionKind::Grasp;
  a.start = 6.0;
  a.approach = 1.0, a.hold = 1.5, a.release = 1.5;
  a.lift = 0.04f;
  return a;
}

// Depth of the fingertip's lowest point below the target.
float depthOf(const HandFrame& f, Finger finger, const HandAction& a) {
  return a.target.y() - (f.fingertips[int(finger)].y() - kRadius);
}

TEST(HandActions, PokeComesDownToItsDepthHoldsAndWithdraws) {
  const HandAction a = poke();
  HandActionsInput input({a}, kRadius);
  EXPECT_TRUE(input.frame(0, 0.5).direct);
  EXPECT_GT(depthOf(input.frame(0, 0.5), Finger::Index, a), -1.5f);  // parked 1 m up until it starts...
  EXPECT_LT(depthOf(input.frame(0, 0.5), Finger::Index, a), -0.9f);
  EXPECT_NEAR(depthOf(input.frame(0, 1.0), Finger::Index, a), -kRadius, 1e-6f);  // ...then one radius above
  EXPECT_NEAR(depthOf(input.frame(0, 2.0), Finger::Index, a), 0.5f * (a.depth - kRadius), 1e-6f);  // halfway down
  EXPECT_NEAR(depthOf(input.frame(0, 3.5), Finger::Index, a), a.depth, 1e-6f);
  EXPECT_NEAR(depthOf(input.frame(0, 4.5), Finger::Index, a), 0.5f * (a.depth - kRadius), 1e-6f);
  // Straight down onto the target, and the other fingertips stay clear.
  const HandFrame held = input.frame(0, 3.5);
  EXPECT_FLOAT_EQ(held.fingertips[int(Finger::Index)].x(), a.target.x());
  EXPECT_FLOAT_EQ(held.fingertips[int(Finger::Index)].z(), a.target.z());
  EXPECT_GT(held.fingertips[int(Finger::Thumb)].y(), a.target.y() + 0.9f);
  EXPECT_FALSE(input.finished(0, 5.0));
  EXPECT_TRUE(input.finished(0, 5.01));
}

// Minimum jerk: 10u^3 - 15u^4 + 6u^5 of the way at the fraction u of the approach (0.1035 at a
// quarter), arriving and leaving at zero speed; linear: u of the way, at constant speed.
TEST(HandActions, APokeMovesAlongItsProfile) {
  HandAction a = poke();  // approach 2 s from t = 1, release 1 s from t = 4
  const float travel = a.depth + kRadius;
  const auto depth = [&](const HandAction& action, double t) {
    HandActionsInput input({action}, kRadius);
    return depthOf(input.frame(0, t), Finger::Index, action);
  };
  EXPECT_NEAR(depth(a, 1.5), -kRadius + 0.103515625f * travel, 1e-6f);
  const double dt = 1e-3;
  const float cruise = travel / 2.0f * 1.875f;  // the profile's peak speed, at half way (m/s)
  EXPECT_NEAR((depth(a, 2.0 + dt) - depth(a, 2.0 - dt)) / float(2 * dt), cruise, 1e-3f * cruise);
  EXPECT_LT(std::abs(depth(a, 3.0 - dt) - depth(a, 3.0 - 2 * dt)) / float(dt), 1e-4f * cruise);  // arrives at rest
  EXPECT_LT(std::abs(depth(a, 4.0 + 2 * dt) - depth(a, 4.0 + dt)) / float(dt), 1e-4f * cruise);  // leaves from rest
  a.profile = PokeProfile::Linear;
  EXPECT_NEAR(depth(a, 1.5), -kRadius + 0.25f * travel, 1e-6f);
  EXPECT_NEAR((depth(a, 3.0 - dt) - depth(a, 3.0 - 2 * dt)) / float(dt), travel / 2.0f, 1e-3f);
}

TEST(HandActions, GraspClosesOnTheTargetLiftsAndLetsGo) {
  const HandAction a = grasp();
  HandActionsInput input({poke(), a}, kRadius);
  const auto gap = [&](double t) {
    const HandFrame f = input.frame(0, t);
    return (f.fingertips[int(Finger::Index)] - f.fingertips[int(Finger::Thumb)]).norm() - 2 * kRadius;
  };
  const auto height = [&](double t) { return input.frame(0, t).fingertips[int(Finger::Thumb)].y(); };
  EXPECT_NEAR(gap(6.0), 4 * kRadius, 1e-6f);  // opens 4 radii by default
  EXPECT_NEAR(gap(6.4), 4 * kRadius, 1e-6f);  // still open at depth...
  EXPECT_NEAR(depthOf(input.frame(0, 6.4), Finger::Thumb, a), a.depth, 1e-6f);
  EXPECT_NEAR(gap(7.0), 2 * kRadius, 1e-6f);              // ...then closed to half the opening
  EXPECT_NEAR(height(7.5) - height(7.0), a.lift, 1e-6f);  // lifted in the first third of the hold
  EXPECT_NEAR(height(8.5) - height(7.0), a.lift, 1e-6f);
  EXPECT_NEAR(height(9.0) - height(7.0), 0.5f * a.lift, 1e-6f);  // lowered half way...
  EXPECT_NEAR(gap(9.5), 4 * kRadius + 0.02f, 1e-6f);             // ...opened wider than it started: it lets go
  EXPECT_NEAR(depthOf(input.frame(0, 10.0 - 1e-9), Finger::Thumb, a), -kRadius - 0.5f * a.lift, 1e-6f);  // rose
  // Thumb and finger either side of the target, level.
  const HandFrame f = input.frame(0, 7.0);
  EXPECT_NEAR(0.5f * (f.fingertips[int(Finger::Thumb)] + f.fingertips[int(Finger::Index)]).x(), a.target.x(), 1e-6f);
  EXPECT_FLOAT_EQ(f.fingertips[int(Finger::Thumb)].y(), f.fingertips[int(Finger::Index)].y());
  EXPECT_TRUE(input.finished(0, 10.01));
}

TEST(HandActions, EachActionAimsOnceAsItStarts) {
  // Given out of order: the aim is asked by the index given, once, at the action's start.
  std::vector<std::size_t> asked;
  const Vec3 moved(0.15f, 0.18f, 0.3f);
  HandActionsInput input({grasp(), poke()}, kRadius, [&](std::size_t index) {
    asked.push_back(index);
    return index == 0 ? Vec3(Vec3::Constant(std::numeric_limits<float>::quiet_NaN())) : moved;
  });
  input.frame(0, 0.5);  // parked above the poke: nothing asked yet
  EXPECT_TRUE(asked.empty());
  HandAction aimed = poke();
  aimed.target = moved;
  for (double t : {1.0, 2.0, 3.5}) {
    const Vec3 tip = input.frame(0, t).fingertips[int(Finger::Index)];
    EXPECT_FLOAT_EQ(tip.x(), moved.x());
    EXPECT_FLOAT_EQ(tip.z(), moved.z());
  }
  EXPECT_NEAR(depthOf(input.frame(0, 3.5), Finger::Index, aimed), aimed.depth, 1e-6f);
  // The grasp's aim is not finite: it keeps its planned target.
  const HandFrame closing = input.frame(0, 7.0);
  EXPECT_FLOAT_EQ(0.5f * (closing.fingertips[0].x() + closing.fingertips[1].x()), grasp().target.x());
  EXPECT_EQ(asked, (std::vector<std::size_t>{1, 0}));
}

TEST(HandActions, RejectsOverlapsThumbGraspsAndBadValues) {
  HandAction late = poke();
  late.start = 4.0;  // the first ends at 5
  EXPECT_NE(testing::errorOf([&] { HandActionsInput({poke(), late}, kRadius); }).find("overlaps"), std::string::npos);
  HandAction thumb = grasp();
  thumb.finger = Finger::Thumb;
  EXPECT_NE(testing::errorOf([&] { HandActionsInput({thumb}, kRadius); }).find("thumb"), std::string::npos);
  HandAction nan = poke();
  nan.depth = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(testing::errorOf([&] { HandActionsInput({nan}, kRadius); }).find("depth"), std::string::npos);
  EXPECT_NE(testing::errorOf([&] { HandActionsInput({}, kRadius); }).find("none"), std::string::npos);
  EXPECT_NE(testing::errorOf([&] { HandActionsInput({poke()}, 0.0f); }).find("radius"), std::string::npos);
}

}  // namespace
}  // namespace vrd
