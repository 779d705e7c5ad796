// A tet's strain and volume constraints in one pass (strain_volume.h): the kernel against the
// strain and volume kernels run one after the other, and the fused solver against the paper's
// order (all strain constraints, then all volume ones) at rest and in stage times.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "random_tet.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/strain_volume.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

TEST(StrainVolume, OnePassEqualsStrainThenVolume) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), comp(0.0f, 0.01f), scale(0.7f, 1.3f);
  int compared = 0;
  for (int trial = 0; trial < 500; ++trial) {
    testing::RandomTet t;
    if (!t.draw(rng, trial)) continue;
    const auto& [x, disp, a, w, restShape] = t;
    // The rest volume need not be the one D_rest was made from (a model may inflate its tets), and
    // a left-handed rest tet has a negative one.
    const float restVolume = scale(rng) * restShape.determinant() / 6.0f;
    StrainLambda lambda;
    for (float& l : lambda) l = 1e-4f * u(rng);
    const float volumeLambda = 1e-4f * u(rng), invH = 60.0f;
    const auto stretch = XpbdCoefficients::make(comp(rng), 0.05f * comp(rng), invH);
    const auto shear = XpbdCoefficients::make(comp(rng), 0.02f * comp(rng), invH);
    const auto volume = XpbdCoefficients::make(0.1f * comp(rng), 0.01f * comp(rng), invH);
    Vec3 start[4], fStart[3];  // the positions at the start of the substep, and F then
    for (int k = 0; k < 4; ++k) start[k] = x[k] - disp[k];
    deformationColumns(start, a, fStart);
    for (const Vec3* d : {static_cast<const Vec3*>(nullptr), static_cast<const Vec3*>(disp)}) {
      const auto fused =
          solveStrainVolume(x, w, a, lambda, stretch, shear, restVolume, volumeLambda, volume, d ? fStart : nullptr);
      // The separate kernels: the volume projection sees the particles, and their motion in the
      // substep, after the strain projection.
      const auto s = solveStrain(x, w, a, lambda, stretch, shear, d);
      Vec3 moved[4], movedDisp[4];
      for (int k = 0; k < 4; ++k) {
        moved[k] = x[k] + s.dp[k];
        movedDisp[k] = (d ? d[k] : Vec3::Zero()) + s.dp[k];
      }
      const auto v = solveVolume(moved, w, restVolume, volumeLambda, volume, d ? movedDisp : nullptr);
      // Same algebra in another order (det F and cofactors instead of face cross products): float
      // rounding of the O(1) quantities, ~1e-5 relative.
      float size = 1e-3f;
      for (int k = 0; k < 4; ++k) size = std::max(size, (s.dp[k] + v.dp[k]).norm());
      for (int k = 0; k < 4; ++k)
        EXPECT_LT((fused.dp[k] - (s.dp[k] + v.dp[k])).norm(), 2e-4f * size) << "trial " << trial;
      for (int c = 0; c < kStrainComponents; ++c)  // the same strain solve
        EXPECT_NEAR(fused.dLambdaStrain[c], s.dLambda[c], 1e-6f * std::abs(s.dLambda[c]));
      // C = V - V0 cancels: its rounding is relative to V0, so the multiplier's is relative to the
      // one a tet squashed flat would get, V0 / ((1 + gamma) sum_k w_k |grad_k V|^2 + alphaTilde).
      const auto e = evalVolume(moved[0], moved[1], moved[2], moved[3], restVolume);
      float gradMinvGrad = 0.0f;
      for (int k = 0; k < 4; ++k) gradMinvGrad += w[k] * e.grad[k].squaredNorm();
      const float flat = std::abs(restVolume) / ((1.0f + volume.gamma) * gradMinvGrad + volume.alphaTilde);
      EXPECT_NEAR(fused.dLambdaVolume, v.dLambda, 2e-4f * (std::abs(v.dLambda) + flat)) << "trial " << trial;
      ++compared;
    }
  }
  EXPECT_GT(compared, 200);
}

// A block pinned at one end sags under gravity; settled with many iterations, the fused pass and
// the paper's order reach the same equilibrium (both are Gauss-Seidel orders of one system).
std::vector<Vec3> settledCantilever(bool fused) {
  Material m;
  m.elastic = ElasticModuli{1e5f, 0.3f, 1000.0f, 0.0f};
  const auto model = makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3(0.3f, 0.05f, 0.05f), 12, 2, 2), m);
  SolverSettings s;
  s.iterations = 50;
  s.substeps = 4;
  s.linearDamping = 5.0f;  // settle quickly
  s.fuseStrainVolume = fused;
  World w(s);
  const BodyId b = w.addBody(model);
  for (Index i = 0; i < model->particleCount(); ++i)
    if (model->restPositions[i].x() < 1e-6f) w.setInverseMass(w.particleIndex(b, i), 0.0f);
  for (int step = 0; step < 240; ++step) w.step();
  std::vector<Vec3> x;
  for (Index i = 0; i < model->particleCount(); ++i) x.push_back(w.particles().x[w.particleIndex(b, i)].pos);
  return x;
}

TEST(StrainVolume, SettlesWhereThePapersOrderSettles) {
  const std::vector<Vec3> paper = settledCantilever(false), fused = settledCantilever(true);
  float sag = 0.0f, worst = 0.0f;
  for (std::size_t i = 0; i < paper.size(); ++i) {
    sag = std::max(sag, -paper[i].y());
    worst = std::max(worst, (paper[i] - fused[i]).norm());
  }
  EXPECT_GT(sag, 0.005f);  // it does bend
  EXPECT_LT(worst, 0.01f * sag) << "sag " << sag;
}

TEST(StrainVolume, TimedAsOneStageOrAsThePapersTwo) {
  const auto model = makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Constant(0.1f), 3, 3, 3), Material{});
  for (bool fused : {true, false}) {
    SolverSettings s;
    s.fuseStrainVolume = fused;
    World w(s);
    w.addBody(model);
    w.step();
    const StageTimes& t = w.lastStep().times;
    EXPECT_EQ(t[Stage::StrainVolume] > 0.0, fused);
    EXPECT_EQ(t[Stage::Strain] > 0.0, !fused);
    EXPECT_EQ(t[Stage::Volume] > 0.0, !fused);
  }
}

// A hand-built model may put its volume constraints on other tets than its strain ones, or on
// fewer: then the two cannot share a pass, and the solver keeps the paper's order.
TEST(StrainVolume, UnpairedArraysKeepThePapersOrder) {
  const auto built = makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Constant(0.1f), 3, 3, 3), Material{},
                                  ConstraintSet::paper(), SolveOrder::Mesh);
  BodyModel reversed = *built, fewer = *built;
  std::reverse(reversed.volume.begin(), reversed.volume.end());
  fewer.volume.resize(fewer.volume.size() / 2);
  for (const BodyModel& model : {reversed, fewer}) {
    World w;
    const BodyId b = w.addBody(std::make_shared<const BodyModel>(model));
    EXPECT_FALSE(w.body(b).tetsPaired);
    w.step();
    const StageTimes& t = w.lastStep().times;
    EXPECT_EQ(t[Stage::StrainVolume], 0.0);
    EXPECT_GT(t[Stage::Strain], 0.0);
    EXPECT_GT(t[Stage::Volume], 0.0);
    EXPECT_LT(std::abs(w.volumeLoss(b)), 0.01);
  }
  World w;
  EXPECT_TRUE(w.body(w.addBody(built)).tetsPaired);
}

}  // namespace
}  // namespace vrd
