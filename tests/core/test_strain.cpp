// Strain constraints (eqs. 29-34): the closed-form kernel against the step-by-step reference, and
// the separation of stretch and shear multipliers under pure stretch and pure shear.

#include <gtest/gtest.h>

#include <random>

#include "random_tet.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

TEST(Strain, ClosedFormKernelMatchesReference) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), comp(0.0f, 0.01f);
  int compared = 0;
  for (int trial = 0; trial < 500; ++trial) {
    testing::RandomTet t;
    if (!t.draw(rng, trial)) continue;
    const auto& [x, disp, a, w, restShape] = t;
    StrainLambda lambda;
    for (float& l : lambda) l = 1e-4f * u(rng);
    const float invH = 60.0f;
    const auto stretch = XpbdCoefficients::make(comp(rng), 0.05f * comp(rng), invH);
    const auto shear = XpbdCoefficients::make(comp(rng), 0.02f * comp(rng), invH);
    const Mat3 invRest = restShape.inverse();
    for (const Vec3* d : {static_cast<const Vec3*>(nullptr), static_cast<const Vec3*>(disp)}) {
      const auto fast = solveStrain(x, w, a, lambda, stretch, shear, d);
      const auto ref = solveStrainReference(x, w, invRest, lambda, stretch, shear, d);
      // Same algebra in a different order: float rounding of the O(1) quantities, ~1e-5 relative.
      // A multiplier is a difference of such terms, so its error has a floor of about 1e-4 of
      // them (2e-4: Eigen's products fuse multiply-adds on aarch64 and round differently).
      float scale = 1e-3f;
      for (int k = 0; k < 4; ++k) scale = std::max(scale, ref.dp[k].norm());
      for (int k = 0; k < 4; ++k) EXPECT_LT((fast.dp[k] - ref.dp[k]).norm(), 2e-4f * scale) << "trial " << trial;
      for (int c = 0; c < kStrainComponents; ++c)
        EXPECT_NEAR(fast.dLambda[c], ref.dLambda[c], 2e-4f * (std::abs(ref.dLambda[c]) + 2e-4f)) << "trial " << trial;
      ++compared;
    }
  }
  EXPECT_GT(compared, 200);
}

// A block whose boundary particles are held (kinematic) at x = F X for a homogeneous F while the
// interior is free. With equal tet volumes (Kuhn cells) a homogeneous deformation is an
// equilibrium, so the interior settles on x = F X and every tet sees the same F; at rest each
// multiplier is lambda = -C(F)/alphaTilde. Strain constraints only. The strain is kept small (2%)
// and the compliance soft so that each step's Gauss-Seidel excursion is tiny: XPBD evaluates each
// gradient where the particles are during the sweep (XPBD16 section 4 drops the change of grad C),
// which leaves a bias of order excursion x curvature, ~1e-4 relative here; tolerance 1e-3.
struct HomogeneousBlock {
  static constexpr float kCompliance = 1.0f;
  World world;
  BodyId body;

  float alphaTilde() const { return kCompliance / (world.substepSize() * world.substepSize()); }

  explicit HomogeneousBlock(const Mat3& F) : world(settings()) {
    Material m;
    m.particleMass = 1.0f;  // the paper's: the soft compliance keeps each step's excursion tiny
    m.strainStretch = {kCompliance, 0.0f};
    m.strainShear = {kCompliance, 0.0f};
    const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 3, 3, 3);
    body = world.addBody(makeSoftBody(mesh, m, {false, false, true, false}));
    for (Index v = 0; v < mesh.vertices.size(); ++v) {
      const Vec3& X = mesh.vertices[v];
      const Index i = world.particleIndex(body, v);
      const bool boundary = (X.array() < 1e-6f).any() || (X.array() > 1.0f - 1e-6f).any();
      world.particles().x[i].pos = boundary ? Vec3(F * X) : X;  // interior starts undeformed
      if (boundary) world.setInverseMass(i, 0.0f);
    }
    for (int s = 0; s < 200; ++s) world.step();
  }
  static SolverSettings settings() {
    SolverSettings s;
    s.gravity.setZero();
    s.iterations = 10;
    s.linearDamping = 5.0f;
    return s;
  }
};

TEST(Strain, PureStretchProducesOnlyStretchMultipliers) {
  const HomogeneousBlock block(Vec3(1.02f, 1.0f, 1.0f).asDiagonal());
  // S = diag(1.02^2, 1, 1): only C_00 = 0.0404 is violated.
  const float expected = (1.02f * 1.02f - 1.0f) / block.alphaTilde();
  const StrainLambdas& lambdas = block.world.body(block.body).strainLambda;
  ASSERT_GT(lambdas.size(), 0u);
  for (std::size_t j = 0; j < lambdas.size(); ++j) {
    const StrainLambda l = lambdas[j];
    EXPECT_NEAR(-l[0], expected, 1e-3f * expected);
    for (int c = 1; c < kStrainComponents; ++c) EXPECT_LT(std::abs(l[c]), 1e-3f * expected) << "component " << c;
  }
}

TEST(Strain, PureShearProducesOnlyShearMultipliers) {
  // Columns of F stay unit length (S_ii = 1) and f0.f1 = sin(0.02): only C_01 is violated.
  Mat3 F = Mat3::Identity();
  F.col(1) = Vec3(std::sin(0.02f), std::cos(0.02f), 0.0f);
  const HomogeneousBlock block(F);
  const float expected = std::sin(0.02f) / block.alphaTilde();
  const StrainLambdas& lambdas = block.world.body(block.body).strainLambda;
  ASSERT_GT(lambdas.size(), 0u);
  for (std::size_t j = 0; j < lambdas.size(); ++j) {
    const StrainLambda l = lambdas[j];
    EXPECT_NEAR(-l[3], expected, 1e-3f * expected);
    for (int c : {0, 1, 2, 4, 5}) EXPECT_LT(std::abs(l[c]), 1e-3f * expected) << "component " << c;
  }
}

}  // namespace
}  // namespace vrd
