// Contacts with static colliders (normal force, Coulomb friction, compliance) and with fingertip
// spheres (eqs. 36-39), checked against closed-form answers.

#include <gtest/gtest.h>

#include "block_on_ground.h"
#include "test_support.h"

#include <cmath>
#include <numbers>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

constexpr float kG = 9.81f;

std::shared_ptr<BodyModel> singleParticle(const Vec3& at, float mass = 1.0f) {
  auto m = std::make_shared<BodyModel>();
  m->restPositions = {at};
  m->invMass = {1.0f / mass};
  return m;
}

// A particle on a plane tilted by theta about z, starting at rest on the surface.
struct Incline {
  World world{[] {
    SolverSettings s;
    s.gravity = Vec3(0.0f, -kG, 0.0f);
    return s;
  }()};
  Vec3 downhill;

  Incline(float theta, float staticFriction, float dynamicFriction) {
    const Vec3 normal(-std::sin(theta), std::cos(theta), 0.0f);
    downhill = Vec3(-std::cos(theta), -std::sin(theta), 0.0f);
    Collider plane = Collider::plane(normal);
    plane.staticFriction = staticFriction;
    plane.dynamicFriction = dynamicFriction;
    world.addCollider(plane);
    world.addBody(singleParticle(Vec3::Zero()));
  }
};

TEST(Contact, StaticFrictionHoldsBelowTheFrictionAngle) {
  // tan 20 deg = 0.364 < mu_s = 0.5: the friction needed, m g sin(theta), fits in the cone.
  Incline incline(20.0f * std::numbers::pi_v<float> / 180.0f, 0.5f, 0.3f);
  for (int step = 0; step < 60; ++step) incline.world.step();
  EXPECT_LT(incline.world.particles().x[0].pos.norm(), 1e-6f);
  EXPECT_LT(incline.world.particles().v[0].norm(), 1e-5f);
}

TEST(Contact, DynamicFrictionGivesTheCoulombAcceleration) {
  // tan 30 deg = 0.577 > mu_s = 0.5: it slides with a = g (sin(theta) - mu_k cos(theta)).
  const float theta = 30.0f * std::numbers::pi_v<float> / 180.0f, muK = 0.3f;
  Incline incline(theta, 0.5f, muK);
  for (int step = 0; step < 60; ++step) incline.world.step();
  const float a = kG * (std::sin(theta) - muK * std::cos(theta));
  const Vec3 v = incline.world.particles().v[0];
  EXPECT_NEAR(v.dot(incline.downhill), a * 1.0f, 1e-3f * a);  // after 1 s; exact in the discrete scheme
  EXPECT_LT(std::abs(v.dot(Vec3(-std::sin(theta), std::cos(theta), 0.0f))), 1e-4f);  // stays on the plane
}

TEST(Contact, CompliantGroundSinksByAlphaMG) {
  // C + alphaTilde lambda = 0 with lambda = m g h^2 at rest: depth = alpha m g.
  SolverSettings s;
  s.linearDamping = 2.0f;
  World w(s);
  Collider ground = Collider::plane(Vec3::UnitY());
  ground.compliance = 1e-4f;
  w.addCollider(ground);
  w.addBody(singleParticle(Vec3::Zero(), 2.0f));
  for (int step = 0; step < 300; ++step) w.step();
  EXPECT_NEAR(-w.particles().x[0].pos.y(), 1e-4f * 2.0f * kG, 1e-3f * 1e-4f * 2.0f * kG);
}

TEST(Contact, RestsOnSphereAndBoxAtItsRadius) {
  World w;
  Collider sphere = Collider::sphere(Vec3(0.0f, 0.0f, 0.0f), 0.5f);
  Collider box = Collider::box(Vec3(3.0f, 0.0f, 0.0f), Vec3(0.4f, 0.3f, 0.2f));
  w.addCollider(sphere);
  w.addCollider(box);
  auto model = singleParticle(Vec3::Zero());
  model->particleRadius = 0.02f;
  const BodyId onSphere = w.addBody(model, Vec3(0.0f, 1.0f, 0.0f));
  const BodyId onBox = w.addBody(model, Vec3(3.0f, 1.0f, 0.0f));
  for (int step = 0; step < 120; ++step) w.step();
  // Dropped from 1 m: 4.4 m/s at impact, 0.07 m per step, no tunnelling; rests at radius 0.02.
  EXPECT_NEAR(w.particles().x[w.particleIndex(onSphere, 0)].pos.y(), 0.52f, 1e-4f);
  EXPECT_NEAR(w.particles().x[w.particleIndex(onBox, 0)].pos.y(), 0.32f, 1e-4f);
}

using testing::BlockOnGround;

TEST(Contact, GroundReactionEqualsWeightAtRest) {
  BlockOnGround block;
  for (int step = 0; step < 240; ++step) block.world.step();
  // Momentum balance at rest (validation.md V12a): sum lambda/h^2 = M g, to 1e-3.
  EXPECT_NEAR(block.groundReaction(), block.weight, 1e-3f * block.weight);
  // The per-particle readout says the same: net constraint force = weight, upward.
  Vec3 total = Vec3::Zero();
  for (const Vec3& f : block.world.particleConstraintForces(block.body)) total += f;
  EXPECT_NEAR(total.y(), block.weight, 1e-3f * block.weight);
  EXPECT_LT(total.head<1>().norm() + std::abs(total.z()), 1e-3f * block.weight);
  // Without the contacts, the material's own forces are internal: they add up to nothing.
  Vec3 internal = Vec3::Zero();
  for (const Vec3& f : block.world.particleMaterialForces(block.body)) internal += f;
  EXPECT_LT(internal.norm(), 1e-3f * block.weight);
}

TEST(Contact, FingertipPushBalancesGroundReaction) {
  // validation.md V12a: a kinematic sphere pressed into a block on the ground; at rest the
  // fingertip force equals the ground reaction minus the weight, to 1e-3, whether it touches the
  // particles (eqs. 36-39) or the surface triangles.
  for (FingertipContactMode mode : {FingertipContactMode::Particles, FingertipContactMode::Triangles}) {
    SCOPED_TRACE(mode == FingertipContactMode::Particles ? "particles" : "triangles");
    BlockOnGround block;
    const FingertipId tip = block.world.addFingertip(Vec3(0.0f, 0.2f, 0.0f), 0.03f, 0.0f, mode);
    for (int step = 0; step < 60; ++step) block.world.step();                // settle first
    block.world.moveFingertip(tip, Vec3(0.0f, 0.1f + 0.03f - 0.01f, 0.0f));  // 1 cm into the top face
    for (int step = 0; step < 300; ++step) block.world.step();
    const Vec3 push = block.world.fingertipForce(tip);
    ASSERT_GT(block.world.fingertipContactCount(tip), 0u);
    ASSERT_GT(-push.y(), 0.1f * block.weight);  // a real push, not noise
    EXPECT_NEAR(-push.y(), block.groundReaction() - block.weight, 1e-3f * block.groundReaction());
    // The per-particle readout includes the fingertip contacts: the net constraint force is the weight.
    Vec3 total = Vec3::Zero();
    for (const Vec3& f : block.world.particleConstraintForces(block.body)) total += f;
    EXPECT_NEAR(total.y(), block.weight, 1e-3f * block.groundReaction());
  }
}

TEST(Contact, FingertipForceDoesNotDependOnTheSubstep) {
  // validation.md V12c: lambda scales as h^2, so lambda/h^2 at rest must not change when the
  // substep is halved (to 1%), with lambda read from the last substep (P9). This holds once the
  // iterations converge: at h = 1/60 with 20 iterations the rest state itself still depends on h
  // (2.7 vs 3.7 N), so the check runs at h = 1/120 and 1/240 with 50 iterations. The fingertip
  // goes 1.5 cm deep so that it rests on several particles, not balanced on one.
  float force[2];
  for (int n : {2, 4}) {
    BlockOnGround block(0.1f, 4, n);
    SolverSettings s = block.world.settings();
    s.iterations = 50;
    block.world.setSettings(s);
    const FingertipId tip = block.world.addFingertip(Vec3(0.0f, 0.2f, 0.0f), 0.03f);
    for (int step = 0; step < 60; ++step) block.world.step();
    block.world.moveFingertip(tip, Vec3(0.0f, 0.1f + 0.03f - 0.015f, 0.0f));
    for (int step = 0; step < 300; ++step) block.world.step();
    force[n / 4] = -block.world.fingertipForce(tip).y();
    vrd::testing::record(n == 2 ? "force_h" : "force_h_over_2", force[n / 4]);
  }
  ASSERT_GT(force[0], 0.1f * BlockOnGround().weight);
  EXPECT_NEAR(force[1], force[0], 0.01f * force[0]);
}

TEST(Contact, FingertipKeepsParticlesOutOfItsSphere) {
  // Eqs. 36-39 with zero compliance: every particle of N(r) ends on or outside the sphere.
  BlockOnGround block;
  const Vec3 centre(0.0f, 0.11f, 0.0f);
  const FingertipId tip = block.world.addFingertip(centre, 0.03f);
  for (int step = 0; step < 30; ++step) block.world.step();
  ASSERT_GT(block.world.fingertipContactCount(tip), 0u);
  for (const FingertipContact& c : block.world.fingertipContacts())
    EXPECT_GE((block.world.particles().x[c.particle].pos - centre).norm(), 0.03f - 1e-5f);
}

}  // namespace
}  // namespace vrd
