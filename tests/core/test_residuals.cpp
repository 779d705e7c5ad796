// The convergence readout (StepReport::residuals) and the adaptive iteration budget
// (SolverSettings::tolerance) on a soft block settling on the ground.

#include <gtest/gtest.h>

#include <cmath>

#include "block_on_ground.h"
#include "test_support.h"

namespace vrd {
namespace {

using testing::BlockOnGround;

// A soft block (the contact tests' block) on frictionless ground after `steps` steps with
// `iterations` per substep, its last step measured. (On a frictional ground the particles at the
// edge of the friction cone switch between sticking and sliding from one iteration to the next,
// and the corrections level off instead of falling towards 0.)
StepReport settled(int iterations, int steps, float tolerance = 0.0f) {
  SolverSettings s = BlockOnGround::settings(1);
  s.iterations = iterations;
  s.measureResiduals = true;
  s.tolerance = tolerance;
  World world(s);
  Material m;
  m.elastic = ElasticModuli{2e4f, 0.3f, BlockOnGround::kDensity};
  world.addBody(makeSoftBody(makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3::Constant(0.1f), 4, 4, 4), m,
                             {false, true, true, false}));
  Collider ground = Collider::plane(Vec3::UnitY());
  ground.staticFriction = ground.dynamicFriction = 0.0f;
  world.addCollider(ground);
  for (int k = 0; k < steps; ++k) world.step();
  return world.lastStep();
}

TEST(Residuals, FallWithIterations) {
  // The block's constraints (strain + volume in one pass) and the ground contacts, mid-settle.
  double previous = INFINITY;
  for (int iterations : {2, 8, 32}) {
    const StepReport r = settled(iterations, 10);
    const Residual tets = r.residuals[std::size_t(Stage::StrainVolume)];
    ASSERT_TRUE(std::isfinite(tets.rms)) << iterations;
    EXPECT_LE(tets.rms, tets.max);
    EXPECT_LT(tets.max, 0.5 * previous) << iterations << " iterations";
    previous = tets.max;
    EXPECT_TRUE(std::isfinite(r.residuals[std::size_t(Stage::Contact)].max));
    EXPECT_TRUE(std::isnan(r.residuals[std::size_t(Stage::Distance)].max)) << "no distance constraints";
    EXPECT_EQ(r.iterations, iterations);
    testing::record("strain_volume_max_" + std::to_string(iterations), tets.max);
  }
}

TEST(Residuals, AreNotMeasuredUnlessAskedAndDoNotChangeTheResult) {
  for (int threads : {1, 2}) {
    BlockOnGround plain, measuring;
    SolverSettings s = plain.world.settings();
    s.threads = threads;
    s.threadsFallBack = false;
    plain.world.setSettings(s);
    s.measureResiduals = true;
    measuring.world.setSettings(s);
    for (int k = 0; k < 20; ++k) plain.world.step(), measuring.world.step();
    for (const Residual& r : plain.world.lastStep().residuals) EXPECT_TRUE(std::isnan(r.max));
    for (std::size_t i = 0; i < plain.world.particles().x.size(); ++i)
      ASSERT_EQ(plain.world.particles().x[i].pos, measuring.world.particles().x[i].pos) << threads << " threads";
  }
}

TEST(Residuals, AdaptiveBudgetMeetsItsTolerance) {
  const float tolerance = 1e-3f;
  const StepReport r = settled(500, 10, tolerance);  // a cap far above what it needs
  EXPECT_GT(r.iterations, 2);
  EXPECT_LT(r.iterations, 500);
  for (const Residual& residual : r.residuals)
    if (std::isfinite(residual.max)) {
      EXPECT_LT(residual.max, tolerance);
    }
  // With a cap below what it needs, it stops at the cap.
  EXPECT_EQ(settled(2, 10, 1e-9f).iterations, 2);
  testing::record("adaptive_iterations", r.iterations);
}

TEST(Residuals, ToleranceIsValidated) {
  SolverSettings s;
  s.tolerance = -1.0f;
  EXPECT_NE(testing::errorOf([&] { validateSolverSettings(s); }).find("tolerance"), std::string::npos);
}

}  // namespace
}  // namespace vrd
