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

using testing::kG;

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

// A particle resting on top of a fingertip with gravity tilted by theta from the contact's normal
// (a sphere of 100 m, flat where it sits): the fingertip's friction acts as a collider's.
struct OnFingertip {
  World world;
  FingertipId tip;
  static constexpr float kRadius = 100.0f;

  OnFingertip(float theta, FingertipFriction friction) {
    SolverSettings s;
    s.gravity = kG * Vec3(std::sin(theta), -std::cos(theta), 0.0f);  // downhill: +x
    world.setSettings(s);
    tip = world.addFingertip(Vec3::Zero(), kRadius);
    world.setFingertipFriction(tip, friction);
    world.addBody(singleParticle(Vec3(0.0f, kRadius, 0.0f)));
  }
  float downhill() const { return world.particles().x[0].pos.x(); }
};

TEST(Contact, FingertipFrictionHoldsBelowTheFrictionAngle) {
  const float theta = 20.0f * std::numbers::pi_v<float> / 180.0f;  // tan 20 deg = 0.364 < mu_s = 0.5
  OnFingertip on(theta, {0.5f, 0.3f});
  for (int step = 0; step < 60; ++step) on.world.step();
  EXPECT_LT(std::abs(on.downhill()), 1e-5f);
  // The fingertip carries the weight, its friction the part along the surface: f_t / f_n = tan(theta).
  const Vec3 f = on.world.fingertipForce(on.tip);
  EXPECT_NEAR(std::abs(f.x() / f.y()), std::tan(theta), 2e-3f * std::tan(theta));
}

TEST(Contact, FingertipFrictionSlidesWithTheCoulombAcceleration) {
  const float theta = 30.0f * std::numbers::pi_v<float> / 180.0f, muK = 0.3f;  // tan 30 deg = 0.577 > 0.5
  OnFingertip on(theta, {0.5f, muK}), bare(theta, {});
  for (int step = 0; step < 30; ++step) on.world.step(), bare.world.step();
  // After 0.5 s, v = a t down the slope (exact in the discrete scheme): a = g (sin - mu_k cos), and
  // g sin(theta) without friction, as on the paper's frictionless fingertips. The sphere turns by
  // 0.006 rad under it: 1% at most.
  const float a = kG * (std::sin(theta) - muK * std::cos(theta)), free = kG * std::sin(theta);
  EXPECT_NEAR(on.world.particles().v[0].x(), 0.5f * a, 0.01f * 0.5f * a);
  EXPECT_NEAR(bare.world.particles().v[0].x(), 0.5f * free, 0.01f * 0.5f * free);
}

// Triangle contacts: a fingertip pressed 2 mm into a block on frictionless ground, then moved 3 cm
// sideways over a second. Its friction drags the block along; without friction it rides over the
// shallow dent it makes.
TEST(Contact, FingertipFrictionDragsTheSurfaceItPresses) {
  const auto dragged = [](FingertipFriction friction) {
    World world(testing::BlockOnGround::settings(1));
    Material m;
    m.elastic = ElasticModuli{2e4f, 0.3f, 1000.0f};
    const BodyId body = world.addBody(makeSoftBody(
        makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3::Constant(0.1f), 4, 4, 4), m, {false, true, true, false}));
    Collider ground = Collider::plane(Vec3::UnitY());
    ground.staticFriction = ground.dynamicFriction = 0.0f;
    world.addCollider(ground);
    const FingertipId tip = world.addFingertip(Vec3(0.0f, 0.2f, 0.0f), 0.03f, 0.0f, FingertipContactMode::Triangles);
    world.setFingertipFriction(tip, friction);
    const auto centre = [&] {
      float x = 0.0f;
      for (const Point& p : world.particles().x) x += p.pos.x();
      return x / float(world.particles().x.size());
    };
    for (int step = 0; step < 60; ++step) world.step();  // settle
    float top = 0.0f;
    for (const Point& p : world.particles().x) top = std::max(top, p.pos.y());
    const float y = top + 0.03f - 0.002f;
    world.moveFingertip(tip, Vec3(0.0f, y, 0.0f));
    for (int step = 0; step < 60; ++step) world.step();
    const float before = centre();
    for (int step = 1; step <= 60; ++step) {
      world.moveFingertip(tip, Vec3(0.03f * float(step) / 60.0f, y, 0.0f));
      world.step();
    }
    EXPECT_EQ(world.body(body).state, BodyState::Active);
    return centre() - before;
  };
  EXPECT_GT(dragged({0.8f, 0.6f}), 0.015f);  // more than half the fingertip's travel (the block shears)
  EXPECT_LT(std::abs(dragged({})), 0.005f);
}

TEST(Contact, FingertipFrictionIsValidated) {
  World world;
  const FingertipId tip = world.addFingertip(Vec3::Zero(), 0.01f);
  for (const FingertipFriction bad : {FingertipFriction{-0.1f, 0.1f}, FingertipFriction{0.5f, std::nanf("")}})
    EXPECT_NE(testing::errorOf([&] { world.setFingertipFriction(tip, bad); }).find("setFingertipFriction"),
              std::string::npos);
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
  // Momentum balance at rest (docs/validation.md V12a): sum lambda/h^2 = M g, to 1e-3.
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
  // docs/validation.md V12a: a kinematic sphere pressed into a block on the ground; at rest the
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
  // docs/validation.md V12c: lambda scales as h^2, so lambda/h^2 at rest must not change when the
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
