// SIMD lanes: the batch ordering is a valid permutation of independent groups, and the lane
// kernels compute what the scalar kernels compute.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <numeric>
#include <random>

#include "sim/lane_sweeps.h"
#include "sim/solver_team.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/constraint_colouring.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

TEST(Colouring, IsAPermutationOfBalancedIndependentColours) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 12, 10, 11);  // 7,920 tets
  const Colouring c = colourConstraints(mesh.tets);
  std::vector<Index> sorted = c.order;
  std::sort(sorted.begin(), sorted.end());
  for (Index k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
  std::vector<Tet> ordered;
  for (Index k : c.order) ordered.push_back(mesh.tets[k]);
  EXPECT_TRUE(coloursIndependent(ordered, c.colourStart));
  // A vertex of this grid is in up to 24 tets, so there are at least 24 colours; balanced, the
  // colours are of similar size and almost nothing is left to the serial remainder.
  const std::size_t colours = c.colourStart.size() - 1;
  EXPECT_GE(colours, 24u);
  EXPECT_LE(colours, 40u);
  std::size_t smallest = mesh.tets.size(), largest = 0;
  for (std::size_t k = 0; k < colours; ++k) {
    smallest = std::min<std::size_t>(smallest, c.colourStart[k + 1] - c.colourStart[k]);
    largest = std::max<std::size_t>(largest, c.colourStart[k + 1] - c.colourStart[k]);
  }
  EXPECT_LE(largest, 2 * smallest) << smallest << " .. " << largest;
  EXPECT_LE(mesh.tets.size() - c.colourStart.back(), mesh.tets.size() / 100);
  // Filled to whole batches of 16 lanes where the constraints fit: few colours end on a partial batch.
  std::size_t partial = 0;
  for (std::size_t k = 0; k < colours; ++k) partial += (c.colourStart[k + 1] - c.colourStart[k]) % 16 != 0;
  EXPECT_LE(partial, colours / 4);
  // The checker is not vacuous: the mesh's own order as one colour fails.
  EXPECT_FALSE(coloursIndependent(mesh.tets, {0, 8}));
}

TEST(Colouring, TwoThreadGroupsShareNoParticleAndLeaveNothingToTheRemainder) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3(1.0f, 2.0f, 1.0f), 12, 12, 12);  // 10,368 tets
  // The grid's vertices run x fastest and z slowest: only a cut across z keeps neighbours in memory
  // in one slab (y is the longest side), the first half of the vertices in slab 0.
  const Slabs slabs = slabsOf(mesh.vertices, 2);
  EXPECT_EQ(slabs.axis, 2);
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) ASSERT_EQ(slabs.of[v], 2 * v / mesh.vertices.size()) << v;
  EXPECT_EQ(slabsOf(mesh.vertices, 2, 2).axis, 1);  // then y, the next slowest

  const std::vector<std::uint8_t> group = twoThreadGroups(mesh.tets, mesh.vertices);
  std::size_t size[5] = {};
  for (std::uint8_t g : group) ++size[g];
  // Halves of about equal size; the seam next to the cut, in halves: the cut runs through a layer
  // of vertices, so up to two layers of cells; across both cuts up to two by two rows of cells.
  EXPECT_NEAR(double(size[0]), double(size[1]), 0.1 * double(size[0]));
  EXPECT_NEAR(double(size[2]), double(size[3]), 0.2 * double(size[2]));
  EXPECT_LE(size[2] + size[3] + size[4], 2 * mesh.tets.size() / 12);
  EXPECT_LE(size[4], 4 * 12 * 6u);

  const Colouring c = colourConstraints(mesh.tets, 16, group);
  std::vector<Tet> ordered;
  for (Index k : c.order) ordered.push_back(mesh.tets[k]);
  ASSERT_EQ(c.groupColours.size(), 6u);
  EXPECT_TRUE(coloursIndependent(ordered, c.colourStart, c.groupColours));
  // Each group's colours hold all its constraints: none is left to the one-at-a-time remainder,
  // not even group 4's, whose colours are small.
  EXPECT_EQ(c.colourStart.back(), mesh.tets.size());
  for (std::size_t g = 0; g < 5; ++g)
    EXPECT_EQ(c.colourStart[c.groupColours[g + 1]] - c.colourStart[c.groupColours[g]], size[g]) << g;
  // The checker is not vacuous: with group 0's last colour counted in group 1, the pair overlaps.
  std::vector<std::uint32_t> moved = c.groupColours;
  --moved[1];
  EXPECT_FALSE(coloursIndependent(ordered, c.colourStart, moved));
}

TEST(Colouring, ModelWithDependentColourIsRejected) {
  auto model = std::make_shared<BodyModel>(*makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Ones(), 6, 6, 6), Material{}));
  ASSERT_GE(model->tetColours.size(), 2u);
  // Move a tet that shares a particle with the first one into the first colour.
  auto shares = [&](const StrainConstraint& a, const StrainConstraint& b) {
    return std::any_of(std::begin(a.i), std::end(a.i),
                       [&](Index p) { return std::find(std::begin(b.i), std::end(b.i), p) != std::end(b.i); });
  };
  const auto other = std::find_if(model->strain.begin() + model->tetColours[1], model->strain.end(),
                                  [&](const StrainConstraint& c) { return shares(c, model->strain[0]); });
  ASSERT_NE(other, model->strain.end());
  std::swap(model->strain[1], *other);
  World w;
  try {
    w.addBody(model);
    ADD_FAILURE() << "no vrd::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("colour"), std::string::npos) << e.what();
  }
}

// Bending keeps the mesh's order (its convergence at a cloth's few iterations depends on it):
// levelOrder puts the constraints in levels of independent ones such that any two that share a
// particle keep their order, and there are few enough levels for the lanes to fill.
TEST(Colouring, LevelsKeepTheOrderOfConstraintsThatShareAParticle) {
  Material m;
  const auto mesh = makeCloth(makeGridCloth(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), 30, 30), m, SolveOrder::Mesh);
  std::vector<std::array<Index, 4>> bends;
  for (const BendConstraint& b : mesh->bend) bends.push_back({b.i[0], b.i[1], b.i[2], b.i[3]});
  const Colouring c = levelOrder(bends);
  std::vector<Index> sorted = c.order;
  std::sort(sorted.begin(), sorted.end());
  for (Index k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
  std::vector<std::array<Index, 4>> ordered;
  for (Index k : c.order) ordered.push_back(bends[k]);
  EXPECT_TRUE(coloursIndependent(ordered, c.colourStart));
  EXPECT_EQ(c.colourStart.back(), bends.size());  // no remainder
  // Each particle's constraints come in their input order.
  std::vector<Index> lastOf(31 * 31, 0);
  std::vector<bool> seen(31 * 31, false);
  for (Index k : c.order)
    for (Index p : bends[k]) {
      if (seen[p]) {
        ASSERT_LT(lastOf[p], k) << "particle " << p;
      }
      seen[p] = true, lastOf[p] = k;
    }
  // A level per few rows of the grid: an 8-lane batch is mostly full.
  const std::size_t levels = c.colourStart.size() - 1;
  EXPECT_LT(levels, bends.size() / 8) << bends.size() << " constraints";
  // The checker is not vacuous: the input order in as many levels of the same sizes fails.
  EXPECT_FALSE(coloursIndependent(bends, c.colourStart));
}

constexpr std::size_t kLanes = 4;

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

// Bending (eq. 24) in lanes: random bends of both signs and a degenerate pair (triangle A flat:
// no correction, its multiplier let go as the scalar kernel does) give the scalar dLambda and
// corrections, to within what atan2's 1 ulp and float rounding allow.
TEST(Lanes, BendKernelMatchesScalar) {
  const LaneInputs in(47);
  Vec3 x[kLanes][4];
  float rest[kLanes];
  for (std::size_t l = 0; l < kLanes; ++l) {
    // p1, p2 on the edge; p3, p4 across it, folded either way by the random offsets
    const Vec3 p[4] = {Vec3::Zero(), Vec3::UnitX(), Vec3(0.4f, 1.0f, 0.0f), Vec3(0.6f, -1.0f, 0.0f)};
    for (int k = 0; k < 4; ++k) x[l][k] = p[k] + 0.3f * in.x[l][k] - 0.3f * Vec3(k == 1, k == 2, k == 3);
    rest[l] = 0.5f * float(l) - 0.7f;
  }
  x[2][2] = x[2][0] + 0.5f * (x[2][1] - x[2][0]);  // lane 2: p3 on the edge
  V3<Lane4> xl[4], disp[4];
  Lane4 w[4];
  for (int k = 0; k < 4; ++k) {
    xl[k] = in.lanesOf(x, k);
    disp[k] = in.lanesOf(in.disp, k);
    w[k] = in.lanes([&](int l) { return in.w[l][k]; });
  }
  const float invH = 60.0f;
  const auto k4 =
      XpbdCoefficientsT<Lane4>::make(in.lanes([&](int l) { return in.compliance[l]; }), splat<Lane4>(0.002), invH);
  const auto bend = solveBend(xl, w, in.lanes([&](int l) { return rest[l]; }),
                              in.lanes([&](int l) { return in.lambda[l][0]; }), k4, disp);
  for (std::size_t l = 0; l < kLanes; ++l) {
    const auto k1 = XpbdCoefficients::make(in.compliance[l], 0.002f, invH);
    const auto b1 = solveBend(x[l], in.w[l], rest[l], in.lambda[l][0], k1, in.disp[l]);
    EXPECT_NEAR(bend.dLambda[l], b1.dLambda, 1e-5f * std::abs(b1.dLambda)) << "lane " << l;
    for (int k = 0; k < 4; ++k) {
      const Vec3 lane(bend.dp[k].x[l], bend.dp[k].y[l], bend.dp[k].z[l]);
      EXPECT_LT((lane - b1.dp[k]).norm(), 1e-5f * (b1.dp[k].norm() + 1e-6f)) << "lane " << l << ", particle " << k;
      if (l == 2) {
        EXPECT_EQ(b1.dp[k], Vec3::Zero());
      }
    }
  }
}

// A soft block pinned at one side sagging for a second, with damping on (the displacement terms).
// (Not dropped on the ground: a particle just in or out of contact turns rounding into millimetres.)
// Several models: as many bodies in one world (they do not touch each other), their particles in order.
std::vector<Vec3> sagBlocks(const std::vector<std::shared_ptr<const BodyModel>>& models, const SolverSettings& s,
                            int steps = 60) {
  World w(s);
  for (const auto& model : models) {
    const BodyId b = w.addBody(model);
    for (Index i = 0; i < model->particleCount(); ++i)
      if (model->restPositions[i].x() < -0.0499f) w.setInverseMass(w.particleIndex(b, i), 0.0f);
  }
  for (int step = 0; step < steps; ++step) w.step();
  std::vector<Vec3> x;
  for (const Point& p : w.particles().x) x.push_back(p.pos);
  return x;
}
std::vector<Vec3> sagBlock(const std::shared_ptr<const BodyModel>& model, const SolverSettings& s, int steps = 60) {
  return sagBlocks({model}, s, steps);
}

std::shared_ptr<const BodyModel> dampedBlock(int cells, const ConstraintSet& set,
                                             SolveOrder order = SolveOrder::Coloured) {
  Material m;
  m.elastic = ElasticModuli{2e4f, 0.4f, 1000.0f, 0.001f};
  return makeSoftBody(makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3::Constant(0.1f), cells, cells, cells), m, set,
                      order);
}

// Every lane width the CPU has computes the same Gauss-Seidel sweep as the one-at-a-time loops;
// only the rounding of identical operations may differ.
TEST(Lanes, EveryWidthAgreesWithTheReferenceLoops) {
  const auto model = dampedBlock(8, {true, true, true, true});  // 3,072 tets: colours wider than 16 lanes
  bool partialBatch = false;  // some colour ends on a partial batch, so the padded lanes run too
  for (std::size_t k = 0; k + 1 < model->tetColours.size(); ++k)
    partialBatch |= (model->tetColours[k + 1] - model->tetColours[k]) % 16 != 0;
  ASSERT_TRUE(partialBatch);
  SolverSettings s;
  s.simd = SimdLevel::Off;
  const std::vector<Vec3> reference = sagBlock(model, s);
  for (SimdLevel level : {SimdLevel::Sse, SimdLevel::Avx2, SimdLevel::Avx512}) {
    if (!cpuSupports(level)) {
      std::printf("  (this CPU has no %s)\n", simdName(level));
      continue;
    }
    s.simd = level;
    const std::vector<Vec3> x = sagBlock(model, s);
    for (Index i = 0; i < model->particleCount(); ++i)
      ASSERT_LT((x[i] - reference[i]).norm(), 1e-5f) << simdName(level) << ", particle " << i;
  }
}

// Bending in levels (makeCloth, levelOrder) is the mesh order's sweep: with the same distance
// constraints, a cloth pinned at one edge swinging down under gravity ends bit for bit where the
// mesh order one at a time leaves it, and in every lane width within the rounding of atan2 and of
// contracted multiply-adds. (Only for a third of a second: later the cloth folds flat on itself
// in places, where a bend angle near +-pi wraps to the other side on a rounding difference.)
TEST(Lanes, BendLevelsGiveTheMeshOrdersResult) {
  Material m;
  m.particleMass = 0.002f;
  m.distance = {1e-6f, 0.0f};
  m.bending = {0.2f, 0.001f};
  const TriMesh grid = makeGridCloth(Vec3::Zero(), Vec3(0.2f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 0.2f), 24, 24);
  const auto levelled = makeCloth(grid, m);
  ASSERT_GT(levelled->bendLevels.size(), 2u);
  auto meshOrder = std::make_shared<BodyModel>(*levelled);
  meshOrder->bend = makeCloth(grid, m, SolveOrder::Mesh)->bend;
  meshOrder->bendLevels.clear();
  const auto sameBend = [](const BendConstraint& a, const BendConstraint& b) {
    return std::equal(std::begin(a.i), std::end(a.i), std::begin(b.i));
  };
  ASSERT_FALSE(std::equal(meshOrder->bend.begin(), meshOrder->bend.end(), levelled->bend.begin(), sameBend));
  const auto run = [&](const std::shared_ptr<const BodyModel>& model, SimdLevel simd) {
    SolverSettings s;
    s.simd = simd;
    s.iterations = 2;
    World w(s);
    const BodyId b = w.addBody(model);
    for (Index i = 0; i < model->particleCount(); ++i)
      if (model->restPositions[i].z() < 1e-6f) w.setInverseMass(w.particleIndex(b, i), 0.0f);
    for (int step = 0; step < 20; ++step) w.step();
    std::vector<Vec3> x;
    for (const Point& p : w.particles().x) x.push_back(p.pos);
    return x;
  };
  const std::vector<Vec3> reference = run(meshOrder, SimdLevel::Off);
  float swing = 0.0f;
  for (Index i = 0; i < grid.vertices.size(); ++i) swing = std::max(swing, grid.vertices[i].y() - reference[i].y());
  EXPECT_GT(swing, 0.1f);  // it swings down, so the bends work
  const std::vector<Vec3> oneAtATime = run(levelled, SimdLevel::Off);
  for (Index i = 0; i < grid.vertices.size(); ++i) ASSERT_EQ(oneAtATime[i], reference[i]) << "particle " << i;
  for (SimdLevel level : {SimdLevel::Sse, SimdLevel::Avx2, SimdLevel::Avx512}) {
    if (!cpuSupports(level)) continue;
    const std::vector<Vec3> x = run(levelled, level);
    for (Index i = 0; i < grid.vertices.size(); ++i)
      ASSERT_LT((x[i] - reference[i]).norm(), 1e-5f) << simdName(level) << ", particle " << i;
  }
}

// Shape matching in lanes: for any range of particles (so the padded last batch too), every width
// gives the one-at-a-time sums (eq. 25) to double precision, and the one-at-a-time goals, damped
// or not, leaving kinematic particles where they are and writing nothing outside the range.
TEST(Lanes, ShapeMatchOfEveryWidthIsTheOneAtATimeShapeMatch) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const auto vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  constexpr std::size_t n = 40;
  std::vector<Point> pred(n), start(n);
  std::vector<Vec3> offsets(n), lambda(n);
  std::vector<float> mass(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float w = i % 5 == 2 ? 0.0f : 0.5f + 0.5f * std::abs(u(rng));  // some kinematic
    start[i] = {vec(), w};
    pred[i] = {start[i].pos + 0.1f * vec(), w};
    offsets[i] = vec();
    lambda[i] = 1e-3f * vec();
    mass[i] = 1.0f + std::abs(u(rng));
  }
  // Sums of a body 100 m out: float sums would lose its shape to the cancellation of m_i p_i q_i^T.
  std::vector<Point> far = pred;
  for (Point& p : far) p.pos += Vec3(100.0f, -50.0f, 30.0f);
  for (std::size_t begin : {0u, 3u})
    for (std::size_t count = 0; begin + count <= n; ++count) {
      const ShapeMatchSums reference = shapeMatchSums(far.data(), offsets.data(), mass.data(), begin, begin + count);
      double scale = 1e-300;  // of the terms
      for (std::size_t i = begin; i < begin + count; ++i) scale += 200.0 * mass[i] * (1.0 + offsets[i].norm());
      for (SimdLevel level : {SimdLevel::Sse, SimdLevel::Avx2, SimdLevel::Avx512}) {
        if (!cpuSupports(level)) continue;
        ShapeMatchSums s;
        s.weighted.setConstant(7.0), s.Apq.setConstant(7.0);  // to be overwritten
        sweeps::lanePlan(level).widths[0]->shapeMatchSums(far.data(), offsets.data(), mass.data(), begin, begin + count,
                                                          s);
        ASSERT_LE((s.weighted - reference.weighted).norm(), 1e-14 * scale) << simdName(level) << " " << count;
        ASSERT_LE((s.Apq - reference.Apq).norm(), 1e-14 * scale) << simdName(level) << " " << count;
      }
    }

  ShapeMatchFrame frame;
  frame.centroid = vec();
  frame.rotation = Eigen::AngleAxisf(0.7f, vec().normalized()).toRotationMatrix();
  ShapeMatchFrame startFrame;
  startFrame.centroid = vec();
  startFrame.rotation = Eigen::AngleAxisf(0.6f, vec().normalized()).toRotationMatrix();
  const float compliance = 1e-4f, invH = 600.0f;
  for (float tau : {0.0f, 0.002f})
    for (std::size_t begin : {0u, 3u})
      for (std::size_t count = 0; begin + count <= n; ++count) {
        const auto goals = [&](SimdLevel level, std::vector<Point>& p, std::vector<Vec3>& l) {
          p = pred, l = lambda;
          const sweeps::Range r{p.data(), start.data(), invH, nullptr};
          sweeps::lanePlan(level).widths[0]->shapeMatch(offsets.data(), compliance, frame, startFrame, l.data(), tau, r,
                                                        begin, begin + count);
        };
        std::vector<Point> reference;
        std::vector<Vec3> referenceLambda;
        goals(SimdLevel::Off, reference, referenceLambda);
        for (SimdLevel level : {SimdLevel::Sse, SimdLevel::Avx2, SimdLevel::Avx512}) {
          if (!cpuSupports(level)) continue;
          std::vector<Point> p;
          std::vector<Vec3> l;
          goals(level, p, l);
          for (std::size_t i = 0; i < n; ++i) {
            const bool in = i >= begin && i < begin + count;
            SCOPED_TRACE(::testing::Message() << simdName(level) << ", tau " << tau << ", particles [" << begin << ", "
                                              << begin + count << "), particle " << i);
            if (!in || pred[i].w == 0.0f) {  // untouched, bit for bit
              ASSERT_EQ(p[i].pos, pred[i].pos);
              ASSERT_EQ(l[i], lambda[i]);
            } else {
              ASSERT_NE(l[i], lambda[i]);
              ASSERT_LT((p[i].pos - reference[i].pos).norm(), 1e-6f);
              ASSERT_LT((l[i] - referenceLambda[i]).norm(), 1e-6f * referenceLambda[i].norm());
            }
            ASSERT_EQ(p[i].w, pred[i].w);
          }
        }
      }
}

// Two threads sweep a big body's groups two at a time, three share each colour, and a small body
// in the same world is swept by one of them (alone, a small body runs on one thread); either way
// constraints run at once only when they touch disjoint particles, so the result is bit for bit
// the one-thread result.
TEST(Lanes, ThreadsGiveTheOneThreadResultExactly) {
  const auto small = dampedBlock(4, {true, true, true, true});  // 384 tets: not cut
  const auto big = dampedBlock(10, {true, true, true, true});   // 6,000: in groups
  ASSERT_EQ(small->tetGroups.size(), 0u);
  ASSERT_EQ(big->tetGroups.size(), 6u);
  for (const auto& models : {std::vector{small}, std::vector{big}, std::vector{big, small}}) {
    SolverSettings s;
    s.threads = 1;
    const std::vector<Vec3> one = sagBlocks(models, s, 3);
    s.threadsFallBack = false;  // the team every step, however busy the machine
    for (int threads : {2, 3}) {
      s.threads = threads;  // (on a busy machine a barrier may wait for a descheduled thread: few steps)
      const std::vector<Vec3> many = sagBlocks(models, s, 3);
      for (std::size_t i = 0; i < one.size(); ++i)
        ASSERT_EQ(many[i], one[i]) << models.size() << " bodies, " << threads << " threads, particle " << i;
    }
  }
}

// SolverTeam::shareOut hands every item to exactly one member, call after call (each after a
// barrier), whatever the count; a team of one takes them all in order.
TEST(Lanes, ThreadsShareOutEveryItemOnce) {
  const std::vector<std::size_t> counts{0, 1, 2, 5, 37, 1000, 3, 1000};
  std::vector<std::atomic<int>> hits(1000);
  ThreadTeam team(3);
  std::array<std::atomic<std::size_t>, 3> taken{};
  team.run([&](const SolverTeam& member) {
    for (std::size_t count : counts) {
      member.shareOut(count, [&](std::size_t i) {
        hits[i].fetch_add(1, std::memory_order_relaxed);
        taken[std::size_t(member.index)].fetch_add(1, std::memory_order_relaxed);
      });
      member.barrier();
    }
  });
  for (std::size_t i = 0; i < hits.size(); ++i) {
    int expected = 0;
    for (std::size_t count : counts) expected += i < count ? 1 : 0;
    ASSERT_EQ(hits[i].load(), expected) << "item " << i;
  }
  std::size_t total = 0;
  for (const auto& t : taken) total += t.load();
  EXPECT_EQ(total, std::accumulate(counts.begin(), counts.end(), std::size_t{0}));
  std::vector<std::size_t> order;
  SolverTeam{}.shareOut(5, [&](std::size_t i) { order.push_back(i); });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

// Body contact is found by the team too (each member a share of the boxes, the trees' parts and
// the pairs of parts): a block in self-contact dropped onto another on the ground gives the
// one-thread contacts and positions bit for bit.
TEST(Lanes, ThreadsFindTheOneThreadBodyContacts) {
  const auto big = dampedBlock(10, {true, true, true, true});
  const auto drop = [&](int threads) {
    SolverSettings s;
    s.substeps = 2;
    s.threads = threads;
    s.threadsFallBack = false;
    World w(s);
    const BodyId lower = w.addBody(big), upper = w.addBody(big, Vec3(0.01f, 0.102f, 0.0f));
    w.addCollider(Collider::plane(Vec3::UnitY()));
    BodyContactSettings contact;
    contact.self = true;
    w.setBodyContact(lower, contact);
    w.setBodyContact(upper, contact);
    for (Index i = 0; i < big->particleCount(); ++i)
      w.particles().v[w.particleIndex(upper, i)] = Vec3(0.0f, -0.5f, 0.0f);
    std::vector<std::vector<std::uint64_t>> keys;
    for (int step = 0; step < 6; ++step) {
      w.step();
      keys.emplace_back();
      for (const BodyContact& c : w.bodyContacts()) keys.back().push_back(c.key);
    }
    return std::pair{w.particles().x, keys};
  };
  const auto [one, oneKeys] = drop(1);
  ASSERT_GT(oneKeys.back().size(), 100u);  // the blocks touch
  for (int threads : {2, 3}) {
    const auto [many, manyKeys] = drop(threads);
    ASSERT_EQ(manyKeys, oneKeys) << threads << " threads";
    for (std::size_t i = 0; i < one.size(); ++i)
      ASSERT_EQ(many[i].pos, one[i].pos) << threads << " threads, particle " << i;
  }
}

// A world whose steps go to the team or to one thread as TeamChoice decides (here: as its
// settings say, step by step) still gives the one-thread result bit for bit.
TEST(Lanes, SwitchingBetweenTheTeamAndOneThreadKeepsTheResult) {
  const auto big = dampedBlock(10, {true, true, true, true});
  ASSERT_FALSE(big->tetGroups.empty());
  SolverSettings s;
  s.threads = 1;
  World one(s), switching(s);
  for (World* w : {&one, &switching}) {
    const BodyId b = w->addBody(big);
    for (Index i = 0; i < big->particleCount(); ++i)
      if (big->restPositions[i].x() < -0.0499f) w->setInverseMass(w->particleIndex(b, i), 0.0f);
  }
  s.threadsFallBack = false;
  for (int step = 0; step < 8; ++step) {
    s.threads = step % 3 == 2 ? 1 : 2;
    switching.setSettings(s);
    one.step();
    switching.step();
  }
  for (std::size_t i = 0; i < one.particles().x.size(); ++i)
    ASSERT_EQ(switching.particles().x[i].pos, one.particles().x[i].pos) << "particle " << i;
}

// TeamChoice with made-up step times: the faster way nearly always, the other tried for up to 16
// steps at growing intervals (256 steps, doubling up to 2,048), and back soon when the load changes.
int teamSteps(TeamChoice& choice, int steps, double team, double alone) {
  int onTeam = 0;
  for (int k = 0; k < steps; ++k) {
    const bool t = choice.useTeam();
    onTeam += t ? 1 : 0;
    choice.record(t ? team : alone);
  }
  return onTeam;
}

TEST(TeamChoice, TakesTheFasterWayAndTriesTheOtherSeldom) {
  TeamChoice idle, busy;
  for (const int other : {10'000 - teamSteps(idle, 10'000, 0.5e-3, 1e-3), teamSteps(busy, 10'000, 3e-3, 1e-3)}) {
    EXPECT_GE(other, 1 + 10'000 / (2'048 + 16));  // a trial at least every 2,048 steps
    EXPECT_LE(other, 200);                        // 2% of the steps
  }
}

TEST(TeamChoice, FollowsTheMachinesLoad) {
  TeamChoice c;
  EXPECT_LT(teamSteps(c, 5'000, 3e-3, 1e-3), 150);  // busy: alone, 3% of the steps trials
  // Idle again: the next trial of the team, at most 2,048 steps on, switches back.
  EXPECT_GT(teamSteps(c, 3'000, 0.5e-3, 1e-3), 3'000 - 2'048 - 16);
  EXPECT_TRUE(c.useTeam());
  // Occasional long team steps (a member off its core) count as often as they come: one in ten
  // at 8 ms makes the team slower on average (1.25 ms) than one thread (1 ms), which it soon
  // finds out without waiting for its next trial.
  int onTeam = 0;
  for (int k = 0; k < 200; ++k) {
    const bool t = c.useTeam();
    onTeam += t ? 1 : 0;
    c.record(t ? (k % 10 == 9 ? 8e-3 : 0.5e-3) : 1e-3);
  }
  EXPECT_LT(onTeam, 100);
  EXPECT_FALSE(c.useTeam());
}

// The world's constraints under a team: collider and fingertip contacts shared at a particle
// boundary, attachments and triangle contacts on the leader. A block in groups dropped on the
// ground (two colliders, so some particles have two contacts), pressed by a fingertip on its
// particles and one on its surface triangles, one corner held by an attachment; beside it a cloth
// draping over a sphere, whose bending levels one member sweeps before the contacts.
TEST(Lanes, ThreadsGiveTheOneThreadResultExactlyWithContacts) {
  const auto model = dampedBlock(10, {true, true, true, true});
  ASSERT_EQ(model->tetGroups.size(), 6u);
  std::size_t bodyContacts = 0;
  const auto run = [&](int threads, std::size_t& contacts) {
    SolverSettings s;
    s.threads = threads;
    s.threadsFallBack = false;
    s.substeps = 2;  // the team predicts, detects and finalises again between substeps
    World w(s);
    const BodyId b = w.addBody(model, Vec3(0.0f, 0.002f, 0.0f));
    w.addCollider(Collider::plane(Vec3::UnitY()));
    w.addCollider(Collider::plane(Vec3::UnitX(), Vec3(-0.0495f, 0.0f, 0.0f)));  // a wall at one side
    w.addFingertip(Vec3(0.0f, 0.108f, 0.0f), 0.01f, 0.0f, FingertipContactMode::Particles);
    w.addFingertip(Vec3(0.03f, 0.108f, 0.03f), 0.01f, 0.0f, FingertipContactMode::Triangles);
    w.attach(w.particleIndex(b, 0), model->restPositions[0] + Vec3(0.0f, 0.01f, 0.0f));
    Material cloth;
    cloth.particleMass = 0.002f;
    cloth.distance = {1e-6f, 0.0f};
    cloth.bending = {0.5f, 0.0f};
    w.addCollider(Collider::sphere(Vec3(0.2f, 0.0f, 0.1f), 0.05f));  // the cloth drapes over it
    w.addBody(makeCloth(makeGridCloth(Vec3(0.1f, 0.051f, 0.0f), Vec3(0.2f, 0.0f, 0.0f), Vec3(0.0f, 0.0f, 0.2f), 20, 20),
                        cloth));
    // A second block half on the first (body contact, and self-contact on the first), clear of the fingertips.
    w.addBody(dampedBlock(2, {false, true, true, false}), Vec3(-0.07f, 0.1025f, -0.07f), Quat::Identity());
    BodyContactSettings self;
    self.self = true;
    w.setBodyContact(b, self);
    contacts = 0;
    for (int step = 0; step < 5; ++step) {
      w.step();
      contacts += w.lastStep().colliderContacts + w.lastStep().fingertipContacts + w.lastStep().bodyContacts;
      bodyContacts += w.lastStep().bodyContacts;
    }
    std::vector<Vec3> x;
    for (const Point& p : w.particles().x) x.push_back(p.pos);
    return x;
  };
  std::size_t contacts = 0;
  const std::vector<Vec3> one = run(1, contacts);
  EXPECT_GT(contacts, 5 * 121u + 100u);  // the block's bottom layer in every step, and the cloth on the sphere
  EXPECT_GT(bodyContacts, 0u);
  for (int threads : {2, 3}) {
    std::size_t same = 0;
    const std::vector<Vec3> many = run(threads, same);
    EXPECT_EQ(same, contacts);
    for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(many[i], one[i]) << threads << " threads, particle " << i;
  }
}

// A team checks each body's particles in shares; a non-finite one freezes the whole body, as one
// thread does, even where the leader holds none of the body's particles, and the other bodies go
// on bit for bit.
TEST(Lanes, ThreadsContainANonFiniteBodyAsOneThreadDoes) {
  const auto block = dampedBlock(10, {true, true, true, true});  // cut in groups: solved by the team
  const auto small = dampedBlock(2, {true, true, true, true});
  const auto run = [&](int threads) {
    SolverSettings s;
    s.threads = threads;
    s.threadsFallBack = false;
    s.substeps = 2;
    World w(s);
    w.addBody(block, Vec3(0.0f, 0.5f, 0.0f));
    const BodyId sick = w.addBody(small, Vec3(1.0f, 0.5f, 0.0f));  // last in the particles: the last member's
    w.step();
    std::vector<Vec3> before;
    for (Index i = 0; i < w.body(sick).particleCount; ++i)
      before.push_back(w.particles().x[w.particleIndex(sick, i)].pos);
    w.particles().force[w.particleIndex(sick, 5)] = Vec3(0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f);
    w.step();
    const std::vector<SimEvent> events = w.takeEvents();
    EXPECT_EQ(events.size(), 1u) << threads << " threads";
    EXPECT_EQ(w.body(sick).state, BodyState::Frozen) << threads << " threads";
    for (Index i = 0; i < w.body(sick).particleCount; ++i)
      EXPECT_EQ(w.particles().x[w.particleIndex(sick, i)].pos, before[i]) << threads << " threads, particle " << i;
    for (int step = 0; step < 3; ++step) w.step();
    std::vector<Vec3> x;
    for (const Point& p : w.particles().x) x.push_back(p.pos);
    return x;
  };
  const std::vector<Vec3> one = run(1);
  for (int threads : {2, 3}) {
    const std::vector<Vec3> many = run(threads);
    for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(many[i], one[i]) << threads << " threads, particle " << i;
  }
}

// The coloured order is another Gauss-Seidel order: it settles to the same static equilibrium as
// the mesh's order (with any number of threads: see the test above). A block pinned at one end sags under gravity; with
// enough iterations both orders converge, and the tip's sag agrees to well within the solver's residual.
TEST(Lanes, ColouredAndMeshOrderSettleToTheSameEquilibrium) {
  Material m;
  m.elastic = ElasticModuli{1e5f, 0.3f, 1000.0f, 0.0f};
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3(0.3f, 0.05f, 0.05f), 12, 2, 2);
  std::vector<Vec3> settled[2];
  for (SolveOrder order : {SolveOrder::Mesh, SolveOrder::Coloured}) {
    const auto model = makeSoftBody(mesh, m, ConstraintSet::edgesAndVolume(), order);
    SolverSettings s;
    s.iterations = 50;
    s.substeps = 4;
    s.linearDamping = 5.0f;  // settle quickly
    s.simd = order == SolveOrder::Mesh ? SimdLevel::Off : SimdLevel::Best;
    World w(s);
    const BodyId b = w.addBody(model);
    for (Index i = 0; i < model->particleCount(); ++i)
      if (model->restPositions[i].x() < 1e-6f) w.setInverseMass(w.particleIndex(b, i), 0.0f);
    for (int step = 0; step < 240; ++step) w.step();
    for (Index i = 0; i < model->particleCount(); ++i)
      settled[order == SolveOrder::Coloured].push_back(w.particles().x[w.particleIndex(b, i)].pos);
  }
  float sag = 0.0f, worst = 0.0f;
  for (Index i = 0; i < mesh.vertices.size(); ++i) {
    sag = std::max(sag, mesh.vertices[i].y() - settled[0][i].y());
    worst = std::max(worst, (settled[0][i] - settled[1][i]).norm());
  }
  EXPECT_GT(sag, 0.005f);  // it does bend
  EXPECT_LT(worst, 0.01f * sag) << "sag " << sag;
}

}  // namespace
}  // namespace vrd
