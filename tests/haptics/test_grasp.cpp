// Grasping (paper eq. 35, Algorithm 2 lines 3-10): a block on the ground pinched between thumb
// and index, lifted, and let go, in both grasp modes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_support.h"
#include "vrdeform/haptics/haptic_session.h"
#include "vrdeform/mesh/primitives.h"

namespace vrd {
namespace {

constexpr float kHalf = 0.03f;  // the block is 6 cm wide

struct Block {
  World world;
  BodyId body = 0;

  static SolverSettings settings() {
    SolverSettings s;
    s.linearDamping = 2.0f;
    // Converged enough that the block stays where it was put: at 1 substep x 5 iterations this
    // stiff block loses 10% of its volume and wanders up to 15 mm across the ground in half a
    // second, by an amount that depends on the Gauss-Seidel order.
    s.substeps = 4;
    return s;
  }

  Block() {
    world.setSettings(settings());
    Material m;
    m.elastic = ElasticModuli{5e4f, 0.3f, 500.0f, 0.005f};
    body = world.addBody(makeSoftBody(makeBoxTets(Vec3(-kHalf, 0, -kHalf), Vec3::Constant(2 * kHalf), 4, 4, 4), m));
    world.addCollider(Collider::plane(Vec3::UnitY()));
    for (int k = 0; k < 30; ++k) world.step();
  }
  /// The centre of mass, which the body's own constraints never move (their corrections conserve
  /// momentum).
  Vec3 centroid() const {
    const Body& b = world.body(body);
    Vec3 sum = Vec3::Zero();
    float mass = 0.0f;
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
      const Point& x = world.particles().x[i];
      sum += x.pos / x.w;
      mass += 1.0f / x.w;
    }
    return sum / mass;
  }
};

// Thumb on the -x side and index on the +x side at `height`, `gap` apart (centre to centre).
HandFrame pinch(float gap, float height) {
  HandFrame f;
  f.direct = true;
  f.fingertips = {Vec3(-gap / 2, height, 0), Vec3(gap / 2, height, 0), Vec3(0, 0.5f, 0.2f), Vec3(0, 0.5f, 0.3f),
                  Vec3(0, 0.5f, 0.4f)};
  return f;
}

struct GraspRun {
  float restHeight, liftedRise, heldFingerError, droppedHeight, holdLift, weight;
  bool graspedBeforeLift, graspedWhileLifting, releasedAtEnd;
};

GraspRun liftAndDrop(GraspMode mode) {
  Block block;
  HapticSessionSettings s;
  s.grasp.mode = mode;
  const float r = s.hand.geometry.fingertipRadius;
  const float height = kHalf;
  const float open = 2 * (kHalf + r) + 0.02f, closed = 2 * (kHalf + r) - 0.02f;
  HapticSession session(block.world, s, pinch(open, height));
  GraspRun out{};
  out.restHeight = block.centroid().y();
  for (int k = 1; k <= 40; ++k) session.step(pinch(open + (closed - open) * float(k) / 40, height));
  out.graspedBeforeLift = session.grasp().active();
  const float grasped = block.centroid().y();
  for (int k = 1; k <= 60; ++k) session.step(pinch(closed, height + 0.1f * float(k) / 60));
  for (int k = 0; k < 120; ++k) session.step(pinch(closed, height + 0.1f));
  out.graspedWhileLifting = session.grasp().active();
  out.holdLift = 0;
  for (Finger f : {Finger::Thumb, Finger::Index}) out.holdLift += session.grasp().holdForce(block.world, f).y();
  out.weight = 500.0f * std::pow(2 * kHalf, 3.0f) * 9.81f;
  out.liftedRise = block.centroid().y() - grasped;
  // The particle nearest each fingertip stays with it.
  out.heldFingerError = 0;
  for (Finger f : {Finger::Thumb, Finger::Index}) {
    const Vec3 tip = session.rig().target(f);
    float nearest = 1e9f;
    const Body& b = block.world.body(block.body);
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
      nearest = std::min(nearest, (block.world.particles().x[i].pos - tip).norm());
    out.heldFingerError = std::max(out.heldFingerError, nearest);
  }
  for (int k = 1; k <= 10; ++k) session.step(pinch(closed + 0.04f * float(k) / 10, height + 0.1f));
  out.releasedAtEnd = !session.grasp().active();
  for (int k = 0; k < 120; ++k) session.step(pinch(closed + 0.04f, height + 0.1f));
  out.droppedHeight = block.centroid().y() - out.restHeight;
  return out;
}

TEST(Grasp, PaperModeCarriesTheWholeBodyWithTheHand) {
  const GraspRun run = liftAndDrop(GraspMode::Paper);
  ASSERT_TRUE(run.graspedBeforeLift);
  ASSERT_TRUE(run.graspedWhileLifting);
  // Eq. 35 places every particle at its cached position plus the hand's displacement (10 cm)
  // before each step, at rest. In the step the lifted body falls freely (the fingertips are off
  // and the body's own constraints do not move its centre of mass), where on the ground it stood:
  // the centre of mass rises 10 cm less one step of free fall from rest.
  const SolverSettings s = Block::settings();
  const float h = s.timeStep / float(s.substeps), keep = 1.0f - s.linearDamping * h;
  float fall = 0.0f, speed = 0.0f;
  for (int k = 0; k < s.substeps; ++k) speed = keep * speed + 9.81f * h, fall += h * speed;  // World::predict
  EXPECT_NEAR(run.liftedRise, 0.1f - fall, 0.02f * fall);                                    // measured: 0.2%
  EXPECT_TRUE(run.releasedAtEnd);
  EXPECT_NEAR(run.droppedHeight, 0.0f, 0.005f);  // back on the ground
}

TEST(Grasp, LocalModeHoldsThePinchedParticlesAndLetsTheRestHang) {
  const GraspRun run = liftAndDrop(GraspMode::Local);
  ASSERT_TRUE(run.graspedBeforeLift);
  ASSERT_TRUE(run.graspedWhileLifting);
  EXPECT_GT(run.liftedRise, 0.05f);                                                // the block came up with the hand
  EXPECT_LT(run.heldFingerError, HandGeometry::average().fingertipRadius * 1.5f);  // and stayed at the fingers
  EXPECT_TRUE(run.releasedAtEnd);
  EXPECT_NEAR(run.droppedHeight, 0.0f, 0.005f);
}

TEST(Grasp, SqueezingDoesNotFlicker) {
  // Hysteresis: once held, an aperture that wobbles by less than releaseOpening keeps the grasp.
  Block block;
  HapticSessionSettings s;
  const float r = s.hand.geometry.fingertipRadius;
  const float open = 2 * (kHalf + r) + 0.02f, closed = 2 * (kHalf + r) - 0.02f;
  HapticSession session(block.world, s, pinch(open, kHalf));
  for (int k = 1; k <= 40; ++k) session.step(pinch(open + (closed - open) * float(k) / 40, kHalf));
  ASSERT_TRUE(session.grasp().active());
  for (int k = 0; k < 120; ++k) {
    session.step(pinch(closed + 0.8f * s.grasp.releaseOpening * std::sin(0.3f * float(k)), kHalf + 0.02f));
    ASSERT_TRUE(session.grasp().active()) << "step " << k;
  }
}

TEST(Grasp, NeedsTheThumbAndAnotherFingerOnTheBody) {
  Block block;
  HapticSessionSettings s;
  const float r = s.hand.geometry.fingertipRadius;
  // The index presses the block's side while the thumb closes in the air above it.
  auto frame = [&](float t) {
    HandFrame f = pinch(1.0f, kHalf);
    f.fingertips[int(Finger::Index)] = Vec3(kHalf + r + 0.01f - 0.015f * t, kHalf, 0);
    f.fingertips[int(Finger::Thumb)] = Vec3(0.05f - 0.04f * t, 0.15f, 0);
    return f;
  };
  HapticSession session(block.world, s, frame(0));
  bool touched = false;
  for (int k = 1; k <= 60; ++k) {
    touched |= session.step(frame(float(k) / 60)).fingers[int(Finger::Index)].contacts > 0;
    EXPECT_FALSE(session.grasp().active());
  }
  EXPECT_TRUE(touched);
}

TEST(Grasp, DisabledGraspNeverStarts) {
  Block block;
  HapticSessionSettings s;
  s.grasp.enabled = false;
  const float r = s.hand.geometry.fingertipRadius;
  const float open = 2 * (kHalf + r) + 0.02f, closed = 2 * (kHalf + r) - 0.02f;
  HapticSession session(block.world, s, pinch(open, kHalf));
  for (int k = 1; k <= 40; ++k) session.step(pinch(open + (closed - open) * float(k) / 40, kHalf));
  EXPECT_FALSE(session.grasp().active());
  EXPECT_GT(session.haptics().fingers[int(Finger::Thumb)].contacts, 0u);  // it pokes instead
}

TEST(Grasp, RejectsBadSettings) {
  GraspSettings s;
  s.releaseOpening = -1.0f;
  EXPECT_NE(testing::errorOf([&] { Grasp g(s); }).find("releaseOpening"), std::string::npos);
  s = {};
  s.holdCompliance = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(testing::errorOf([&] { Grasp g(s); }).find("holdCompliance"), std::string::npos);
}

}  // namespace
}  // namespace vrd
