// World behaviour: NaN containment, kinematic motion, attachments, timings, measurements.

#include <gtest/gtest.h>

#include <limits>

#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

std::shared_ptr<const BodyModel> smallJelly() {
  Material m;
  m.elastic = ElasticModuli{5e3f, 0.4f, 1000.0f, 0.002f};
  return makeSoftBody(makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3(0.1f, 0.1f, 0.1f), 2, 2, 2), m);
}

TEST(World, NanIsContainedInItsBodyAndReported) {
  World w;
  const BodyId sick = w.addBody(smallJelly(), Vec3(0.0f, 1.0f, 0.0f));
  const BodyId healthy = w.addBody(smallJelly(), Vec3(1.0f, 1.0f, 0.0f));
  for (int s = 0; s < 5; ++s) w.step();
  std::vector<Vec3> before;
  for (Index i = 0; i < w.body(sick).particleCount; ++i)
    before.push_back(w.particles().x[w.particleIndex(sick, i)].pos);
  const float healthyY = w.particles().x[w.particleIndex(healthy, 0)].pos.y();

  w.particles().force[w.particleIndex(sick, 3)] = Vec3(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  w.step();  // step 5

  const std::vector<SimEvent> events = w.takeEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].body, sick);
  EXPECT_EQ(events[0].step, 5u);
  EXPECT_NE(events[0].message.find("frozen"), std::string::npos) << events[0].message;
  EXPECT_EQ(w.body(sick).state, BodyState::Frozen);
  for (Index i = 0; i < w.body(sick).particleCount; ++i) {  // held at its last finite state
    EXPECT_EQ(w.particles().x[w.particleIndex(sick, i)].pos, before[i]);
    EXPECT_TRUE(w.particles().v[w.particleIndex(sick, i)].isZero());
  }
  // The other body keeps falling, and the frozen one stays put through later steps.
  for (int s = 0; s < 5; ++s) w.step();
  EXPECT_LT(w.particles().x[w.particleIndex(healthy, 0)].pos.y(), healthyY - 0.01f);
  EXPECT_EQ(w.particles().x[w.particleIndex(sick, 0)].pos, before[0]);
  EXPECT_TRUE(w.takeEvents().empty());

  w.resetBody(sick);  // the user can bring it back
  EXPECT_EQ(w.body(sick).state, BodyState::Active);
  EXPECT_NEAR(w.particles().x[w.particleIndex(sick, 0)].pos.y(), 1.0f, 1e-6f);
}

TEST(World, ResetPolicyAndNonFiniteStateReset) {
  SolverSettings s;
  s.onNan = NanPolicy::Reset;
  World w(s);
  const BodyId b = w.addBody(smallJelly(), Vec3(0.0f, 1.0f, 0.0f));
  w.step();
  w.particles().v[w.particleIndex(b, 2)] = Vec3(0.0f, std::numeric_limits<float>::infinity(), 0.0f);
  w.step();
  auto events = w.takeEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].message.find("reset"), std::string::npos);
  EXPECT_EQ(w.body(b).state, BodyState::Active);
  for (Index i = 0; i < w.body(b).particleCount; ++i) EXPECT_TRUE(isFinite(w.particles().x[w.particleIndex(b, i)].pos));

  // Under Freeze, a body whose last state is itself not finite cannot be frozen there: it is reset.
  World f;
  const BodyId c = f.addBody(smallJelly());
  f.particles().x[f.particleIndex(c, 0)].pos.x() = std::numeric_limits<float>::quiet_NaN();
  f.step();
  events = f.takeEvents();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_NE(events[0].message.find("reset"), std::string::npos);
  EXPECT_TRUE(isFinite(f.particles().x[f.particleIndex(c, 0)].pos));
}

TEST(World, KinematicParticlesFollowTheirVelocity) {
  SolverSettings s;
  s.substeps = 4;
  World w(s);
  const BodyId b = w.addBody(smallJelly());
  const Index k = w.particleIndex(b, 0);
  w.setInverseMass(k, 0.0f);
  w.particles().v[k] = Vec3(0.6f, 0.0f, 0.0f);
  const Vec3 start = w.particles().x[k].pos;
  for (int i = 0; i < 10; ++i) w.step();
  // Unaffected by gravity and constraints: 0.6 m/s for 10/60 s.
  EXPECT_LT((w.particles().x[k].pos - start - Vec3(0.1f, 0.0f, 0.0f)).norm(), 1e-6f);
}

TEST(World, ConstantForceAcceleratesByForceOverMass) {
  // Algorithm 1, line 7: a = w f on top of gravity; a free 2 kg particle under 20 N along x.
  SolverSettings s;
  s.substeps = 2;
  World w(s);
  auto model = std::make_shared<BodyModel>();
  model->restPositions = {Vec3::Zero()};
  model->invMass = {0.5f};
  const BodyId b = w.addBody(model);
  w.setExternalForce(b, Vec3(20.0f, 0.0f, 0.0f));
  for (int i = 0; i < 60; ++i) w.step();
  EXPECT_NEAR(w.particles().v[0].x(), 10.0f, 1e-4f);  // 10 m/s^2 for 1 s
  EXPECT_NEAR(w.particles().v[0].y(), -9.81f, 1e-4f);
}

TEST(World, AForcePerKilogramAcceleratesLightAndHeavyParticlesAlike) {
  // A 1 kg and a 4 kg particle and a kinematic one, 2 m/s^2 along x per kg plus 1 N each along z.
  SolverSettings s;
  s.gravity.setZero();
  World w(s);
  auto model = std::make_shared<BodyModel>();
  model->restPositions = {Vec3::Zero(), Vec3::UnitY(), Vec3::UnitZ()};
  model->invMass = {1.0f, 0.25f, 0.0f};
  const BodyId b = w.addBody(model);
  w.setExternalForce(b, Vec3(0.0f, 0.0f, 1.0f), Vec3(2.0f, 0.0f, 0.0f));
  EXPECT_EQ(w.particles().force[1], Vec3(8.0f, 0.0f, 1.0f));
  for (int i = 0; i < 60; ++i) w.step();
  for (Index i : {0u, 1u}) EXPECT_NEAR(w.particles().v[i].x(), 2.0f, 1e-4f);  // 1 s
  EXPECT_NEAR(w.particles().v[0].z(), 1.0f, 1e-4f);
  EXPECT_NEAR(w.particles().v[1].z(), 0.25f, 1e-4f);
  EXPECT_EQ(w.particles().v[2], Vec3::Zero());
  EXPECT_THROW(w.setExternalForce(b, Vec3::Zero(), Vec3(std::numeric_limits<float>::infinity(), 0, 0)), Error);
}

TEST(World, MovingAttachmentArrivesAtItsGoal) {
  for (int substeps : {1, 3}) {
    SolverSettings s;
    s.substeps = substeps;
    s.gravity.setZero();
    World w(s);
    auto model = std::make_shared<BodyModel>();
    model->restPositions = {Vec3::Zero()};
    model->invMass = {1.0f};
    w.addBody(model);
    const AttachmentId a = w.attach(0, Vec3::Zero());
    w.moveAttachment(a, Vec3(0.3f, 0.0f, 0.0f));
    w.step();
    EXPECT_LT((w.particles().x[0].pos - Vec3(0.3f, 0.0f, 0.0f)).norm(), 1e-6f);
    // Linear motion over the step: the velocity is the path over the step.
    EXPECT_NEAR(w.particles().v[0].x(), 0.3f * 60.0f, 1e-3f);
    w.detach(a);
    w.step();  // free now: keeps its velocity
    EXPECT_NEAR(w.particles().x[0].pos.x(), 0.6f, 1e-5f);
  }
}

TEST(World, StageTimesCoverTheStagesThatRan) {
  World w;
  const BodyId b = w.addBody(smallJelly());
  w.addCollider(Collider::plane(Vec3::UnitY(), Vec3(0.0f, -0.01f, 0.0f)));
  w.attach(w.particleIndex(b, 0), Vec3(-0.05f, 0.0f, -0.05f));
  w.addFingertip(Vec3(0.0f, 0.12f, 0.0f), 0.03f);
  w.step();
  const StageTimes& t = w.lastStep().times;
  for (Stage s :
       {Stage::Predict, Stage::Detect, Stage::StrainVolume, Stage::ShapeMatching, Stage::Attachment, Stage::Finalise})
    EXPECT_GT(t[s], 0.0) << stageName(s);
  EXPECT_EQ(t[Stage::Distance], 0.0);  // no such constraints
  EXPECT_EQ(t[Stage::Bend], 0.0);
  EXPECT_GE(t.totalMs(), t.solveMs());

  SolverSettings quiet;
  quiet.timeStages = false;
  w.setSettings(quiet);
  w.step();
  EXPECT_EQ(w.lastStep().times.totalMs(), 0.0);
  EXPECT_EQ(w.lastStep().step, 1u);
}

TEST(World, VolumeLossOfAScaledBody) {
  World w;
  const BodyId b = w.addBody(smallJelly());
  EXPECT_NEAR(w.volumeLoss(b), 0.0, 1e-6);
  for (Index i = 0; i < w.body(b).particleCount; ++i) w.particles().x[w.particleIndex(b, i)].pos *= 0.9f;
  EXPECT_NEAR(w.volumeLoss(b), 1.0 - 0.9 * 0.9 * 0.9, 1e-5);  // e = (v0 - v)/v0 with v = 0.9^3 v0
}

TEST(World, BodiesSharingAModelAreIndependent) {
  SolverSettings s;
  s.gravity.setZero();
  World w(s);
  const auto model = smallJelly();
  const BodyId a = w.addBody(model), b = w.addBody(model, Vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(w.body(a).model, w.body(b).model);
  for (Index i = 0; i < w.body(a).particleCount; ++i) w.particles().v[w.particleIndex(a, i)] = Vec3(0.0f, 1.0f, 0.0f);
  for (int i = 0; i < 10; ++i) w.step();
  // b stays at rest (up to the float rounding of its translated rest shape) while a moves 0.17 m.
  for (Index i = 0; i < w.body(b).particleCount; ++i)
    EXPECT_LT((w.particles().x[w.particleIndex(b, i)].pos - Vec3(1.0f, 0.0f, 0.0f) - model->restPositions[i]).norm(),
              1e-6f);
  EXPECT_GT((w.particles().x[w.particleIndex(a, 0)].pos - model->restPositions[0]).norm(), 0.1f);
}

// Issue 6's memory budget: at most 300 bytes per tet, all constraint data, multipliers and
// particle state included. The count is not vacuous: it grows with the constraints a body has.
TEST(World, BodyMemoryStaysWithinThreeHundredBytesPerTet) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 12, 12, 12);  // 10,368 tets
  World w;
  const BodyId light = w.addBody(makeSoftBody(mesh, Material{}, ConstraintSet::edgesAndVolume()));
  const BodyId paper = w.addBody(makeSoftBody(mesh, Material{}, ConstraintSet::paper()));
  const double perTet[2] = {double(w.bodyBytes(light)) / double(mesh.tets.size()),
                            double(w.bodyBytes(paper)) / double(mesh.tets.size())};
  // Lower bounds from the arrays alone: a volume constraint (24 B) and multiplier (4 B) per tet,
  // and for the paper's set a strain constraint (60 B) and six multipliers (24 B) more.
  EXPECT_GT(perTet[0], 28.0);
  EXPECT_GT(perTet[1], perTet[0] + 60.0);
  EXPECT_LE(perTet[0], 300.0);
  EXPECT_LE(perTet[1], 300.0);
}

}  // namespace
}  // namespace vrd
