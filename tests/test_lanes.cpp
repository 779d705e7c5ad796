// SIMD lanes: the batch ordering is a valid permutation of independent groups, and the lane
// kernels compute what the scalar kernels compute.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/lane_batches.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

TEST(Lanes, OrderIsAPermutationOfIndependentGroups) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 7, 5, 6);
  const LaneOrder order = orderForLanes(mesh.tets);
  std::vector<Index> sorted = order.order;
  std::sort(sorted.begin(), sorted.end());
  for (Index k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
  EXPECT_EQ(order.batched % kLanes, 0u);
  EXPECT_GE(order.batched, mesh.tets.size() * 98 / 100);  // the scalar tail stays small
  std::vector<Tet> ordered;
  for (Index k : order.order) ordered.push_back(mesh.tets[k]);
  EXPECT_TRUE(lanesIndependent(ordered, order.batched));
  // The checker is not vacuous: the Kuhn order itself (6 tets per cell share a diagonal) fails.
  EXPECT_FALSE(lanesIndependent(mesh.tets, kLanes));
}

TEST(Lanes, ModelWithDependentBatchIsRejected) {
  auto model = std::make_shared<BodyModel>(*makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Ones(), 4, 4, 4), Material{}));
  ASSERT_GE(model->batchedStrain, 2 * kLanes);
  // Move a tet that shares a particle with lane 0 into lane 1 of the first group.
  auto shares = [&](const StrainConstraint& a, const StrainConstraint& b) {
    return std::any_of(std::begin(a.i), std::end(a.i),
                       [&](Index p) { return std::find(std::begin(b.i), std::end(b.i), p) != std::end(b.i); });
  };
  const auto other = std::find_if(model->strain.begin() + kLanes, model->strain.end(),
                                  [&](const StrainConstraint& c) { return shares(c, model->strain[0]); });
  ASSERT_NE(other, model->strain.end());
  std::swap(model->strain[1], *other);
  World w;
  try {
    w.addBody(model);
    ADD_FAILURE() << "no vrd::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("groups"), std::string::npos) << e.what();
  }
}

// Random tets for the four lanes and the scalar reference.
struct LaneInputs {
  Vec3 x[kLanes][4], disp[kLanes][4];
  float w[kLanes][4];
  Mat3 invRest[kLanes];
  float restVolume[kLanes], compliance[kLanes];
  StrainLambda lambda[kLanes];

  explicit LaneInputs(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), mass(0.1f, 2.0f);
    for (std::size_t l = 0; l < kLanes; ++l) {
      Vec3 rest[4] = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
      Mat3 shape;
      shape << rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0];
      invRest[l] = shape.inverse();
      restVolume[l] = 1.0f / 6.0f;
      compliance[l] = 1e-3f * (l + 1);
      for (int k = 0; k < 4; ++k) {
        x[l][k] = rest[k] + 0.2f * Vec3(u(rng), u(rng), u(rng));
        disp[l][k] = 0.01f * Vec3(u(rng), u(rng), u(rng));
        w[l][k] = mass(rng);
      }
      for (float& v : lambda[l]) v = 1e-4f * u(rng);
    }
  }
  template <typename F>
  Lane4 lanes(F f) const {
    return Lane4{f(0), f(1), f(2), f(3)};
  }
  V3<Lane4> lanesOf(const Vec3 (*v)[4], int k) const {
    return {lanes([&](int l) { return v[l][k].x(); }), lanes([&](int l) { return v[l][k].y(); }),
            lanes([&](int l) { return v[l][k].z(); })};
  }
};

void expectLaneMatches(const V3<Lane4>& lanes, std::size_t l, const Vec3& scalar) {
  const Vec3 lane(lanes.x[l], lanes.y[l], lanes.z[l]);
  EXPECT_LT((lane - scalar).norm(), 1e-6f * (scalar.norm() + 1e-3f)) << "lane " << l;
}

TEST(Lanes, VolumeAndStrainKernelsMatchScalar) {
  const LaneInputs in(31);
  V3<Lane4> x[4], disp[4], a[4];
  Lane4 w[4];
  for (int k = 0; k < 4; ++k) {
    x[k] = in.lanesOf(in.x, k);
    disp[k] = in.lanesOf(in.disp, k);
    w[k] = in.lanes([&](int l) { return in.w[l][k]; });
  }
  const float invH = 60.0f;
  const auto k4 =
      XpbdCoefficientsT<Lane4>::make(in.lanes([&](int l) { return in.compliance[l]; }), splat<Lane4>(0.002), invH);
  const auto vol = solveVolume(x, w, in.lanes([&](int l) { return in.restVolume[l]; }),
                               in.lanes([&](int l) { return in.lambda[l][0]; }), k4, disp);
  for (int k = 0; k < 3; ++k) {
    auto entry = [&](int col) { return in.lanes([&](int l) { return in.invRest[l](k, col); }); };
    a[k + 1] = {entry(0), entry(1), entry(2)};
  }
  a[0] = -(a[1] + a[2] + a[3]);
  StrainLambdaT<Lane4> lambda;
  for (int c = 0; c < kStrainComponents; ++c) lambda[c] = in.lanes([&](int l) { return in.lambda[l][c]; });
  const auto strain = solveStrain(x, w, a, lambda, k4, k4, disp);

  for (std::size_t l = 0; l < kLanes; ++l) {
    const auto k1 = XpbdCoefficients::make(in.compliance[l], 0.002f, invH);
    const auto v1 = solveVolume(in.x[l], in.w[l], in.restVolume[l], in.lambda[l][0], k1, in.disp[l]);
    EXPECT_NEAR(vol.dLambda[l], v1.dLambda, 1e-6f * std::abs(v1.dLambda));
    const auto weights = strainWeights(in.invRest[l]);
    const Vec3 a1[4] = {weights[0], weights[1], weights[2], weights[3]};
    const auto s1 = solveStrain(in.x[l], in.w[l], a1, in.lambda[l], k1, k1, in.disp[l]);
    for (int k = 0; k < 4; ++k) {
      expectLaneMatches(vol.dp[k], l, v1.dp[k]);
      expectLaneMatches(strain.dp[k], l, s1.dp[k]);
    }
    for (int c = 0; c < kStrainComponents; ++c)
      EXPECT_NEAR(strain.dLambda[c][l], s1.dLambda[c], 1e-6f * (std::abs(s1.dLambda[c]) + 1e-6f));
  }
}

TEST(Lanes, WorldWithAndWithoutSimdAgree) {
  // The same Gauss-Seidel order either way; only the rounding of identical operations may differ.
  Material m;
  m.elastic = ElasticModuli{2e4f, 0.4f, 1000.0f, 0.001f};
  const auto model =
      makeSoftBody(makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3::Constant(0.1f), 4, 4, 4), m, {true, true, true, true});
  std::vector<Vec3> result[2];
  for (int simd = 0; simd < 2; ++simd) {
    SolverSettings s;
    s.simd = simd == 1;
    World w(s);
    const BodyId b = w.addBody(model, Vec3(0.0f, 0.02f, 0.0f));
    w.addCollider(Collider::plane(Vec3::UnitY()));
    for (int step = 0; step < 60; ++step) w.step();
    for (Index i = 0; i < model->particleCount(); ++i)
      result[simd].push_back(w.particles().x[w.particleIndex(b, i)].pos);
  }
  for (Index i = 0; i < model->particleCount(); ++i) EXPECT_LT((result[0][i] - result[1][i]).norm(), 1e-5f) << i;
}

}  // namespace
}  // namespace vrd
