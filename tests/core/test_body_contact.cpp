// Body contact's pieces (sim/body_contact.h, sim/surface_tree.h): the contact plane of a vertex and
// a triangle, one projection and its friction, and the broad phase's tree and normal cones, each
// against geometry worked out by hand or against brute force.

#include <gtest/gtest.h>

#include <map>
#include <numeric>
#include <random>

#include "vrdeform/sim/body_contact.h"
#include "vrdeform/sim/surface_tree.h"

namespace vrd {
namespace {

const Vec3 kA(0.0f, 0.0f, 0.0f), kB(1.0f, 0.0f, 0.0f), kC(0.0f, 0.0f, -1.0f);  // normal +y

TEST(VertexTriangleTouch, AboveTheFaceTheNormalIsTheFaces) {
  const auto t = touchVertexTriangle(Vec3(0.25f, 0.1f, -0.25f), kA, kB, kC, true);
  ASSERT_TRUE(t);
  EXPECT_NEAR((t->normal - Vec3::UnitY()).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR(t->distance, 0.1f, 1e-6f);
  const Vec3 q = t->b[0] * kA + t->b[1] * kB + t->b[2] * kC;
  EXPECT_NEAR((q - Vec3(0.25f, 0.0f, -0.25f)).norm(), 0.0f, 1e-6f);
}

TEST(VertexTriangleTouch, BelowAClosedSurfaceTheNormalStaysOutward) {
  // Just inside a soft body's boundary: pushed back out, so the distance is negative.
  const auto closed = touchVertexTriangle(Vec3(0.25f, -0.01f, -0.25f), kA, kB, kC, true);
  ASSERT_TRUE(closed);
  EXPECT_NEAR(closed->normal.y(), 1.0f, 1e-6f);
  EXPECT_NEAR(closed->distance, -0.01f, 1e-6f);
  // A cloth is two-sided: the side the vertex is on.
  const auto open = touchVertexTriangle(Vec3(0.25f, -0.01f, -0.25f), kA, kB, kC, false);
  ASSERT_TRUE(open);
  EXPECT_NEAR(open->normal.y(), -1.0f, 1e-6f);
  EXPECT_NEAR(open->distance, 0.01f, 1e-6f);
}

TEST(VertexTriangleTouch, BesideAnEdgeTheNormalPointsFromTheEdge) {
  // Beyond edge AB (z > 0), above the plane: the closest point is on the edge.
  const auto t = touchVertexTriangle(Vec3(0.5f, 0.03f, 0.04f), kA, kB, kC, true);
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->distance, 0.05f, 1e-6f);
  EXPECT_NEAR((t->normal - Vec3(0.0f, 0.6f, 0.8f)).norm(), 0.0f, 1e-6f);
  EXPECT_NEAR(t->b[2], 0.0f, 1e-7f);
  // Beside the edge but below a closed surface's plane: another face is the one it meets.
  EXPECT_FALSE(touchVertexTriangle(Vec3(0.5f, -0.03f, 0.04f), kA, kB, kC, true));
  EXPECT_TRUE(touchVertexTriangle(Vec3(0.5f, -0.03f, 0.04f), kA, kB, kC, false));
}

TEST(VertexTriangleTouch, DegenerateTrianglesAndVerticesOnAnEdgeMakeNone) {
  EXPECT_FALSE(touchVertexTriangle(Vec3(0.0f, 1.0f, 0.0f), kA, kB, Vec3(2.0f, 0.0f, 0.0f), true));  // collinear
  EXPECT_FALSE(touchVertexTriangle(Vec3(0.0f, 1.0f, 0.0f), kA, kA, kA, true));
  EXPECT_FALSE(touchVertexTriangle(Vec3(0.5f, 0.0f, 0.0f), kA, kB, kC, false));  // on edge AB
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(touchVertexTriangle(Vec3(0.2f, 0.1f, -0.2f), kA, kB, Vec3(nan, 0.0f, 0.0f), true));
}

BodyContact contactOf(const VertexTriangleTouch& t, float gap, float mu = 0.0f) {
  return {{0, 1, 2, 3}, {1.0f, -t.b[0], -t.b[1], -t.b[2]}, 1, 0, Vec3::Zero(), t.normal, {gap, 0.0f, mu, mu}};
}

TEST(EdgeEdgeTouch, CrossedEdgesMeetAtTheirClosestPoints) {
  // Edge along x at height 0.01 above an edge along z: closest points in their middles.
  const auto t =
      touchEdgeEdge(Vec3(-1.0f, 0.01f, 0.0f), Vec3(1.0f, 0.01f, 0.0f), Vec3(0.0f, 0.0f, -0.5f), Vec3(0.0f, 0.0f, 1.5f));
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->s, 0.5f, 1e-6f);
  EXPECT_NEAR(t->t, 0.25f, 1e-6f);
  EXPECT_NEAR(t->distance, 0.01f, 1e-6f);
  EXPECT_NEAR((t->normal - Vec3::UnitY()).norm(), 0.0f, 1e-5f);
  // Parallel edges, edges that meet, and closest points at an end make none.
  EXPECT_FALSE(touchEdgeEdge(Vec3(0, 0.01f, 0), Vec3(1, 0.01f, 0), Vec3(0, 0, 0), Vec3(1, 0, 0)));
  EXPECT_FALSE(touchEdgeEdge(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1), Vec3(0, 0, 1)));
  EXPECT_FALSE(touchEdgeEdge(Vec3(0.5f, 0.01f, 0), Vec3(2, 0.01f, 0), Vec3(0, 0, -1), Vec3(0, 0, 1)));
}

TEST(BodyContactProjection, OneProjectionRestoresTheGapAndConservesMomentum) {
  // The constraint is linear in the positions (a fixed plane), so one rigid projection solves it:
  // C = 0 after, whatever the masses, and sum m dx = 0 since the weights sum to 1 - 1 = 0.
  const std::array<Point, 4> x{Point{Vec3(0.3f, -0.004f, -0.2f), 4.0f}, Point{kA, 2.0f}, Point{kB, 0.5f},
                               Point{kC, 1.0f}};
  const auto touch = touchVertexTriangle(x[0].pos, kA, kB, kC, true);
  ASSERT_TRUE(touch);
  const BodyContact c = contactOf(*touch, 0.002f);
  const BodyContactCorrection r = solveBodyContact(x, c, 0.0f, {0.0f, 0.0f});
  EXPECT_GT(r.dLambda, 0.0f);
  Vec3 d = Vec3::Zero(), momentum = Vec3::Zero();
  for (std::size_t k = 0; k < 4; ++k) {
    d += c.weight[k] * (x[k].pos + r.dx[k]);
    momentum += r.dx[k] / x[k].w;
  }
  EXPECT_NEAR(c.normal.dot(d), 0.002f, 1e-7f);
  EXPECT_NEAR(momentum.norm(), 0.0f, 1e-7f);
  // Separated beyond the gap with no multiplier: nothing.
  std::array<Point, 4> far = x;
  far[0].pos.y() = 0.01f;
  EXPECT_EQ(solveBodyContact(far, c, 0.0f, {0.0f, 0.0f}).dLambda, 0.0f);
  // A multiplier never goes negative: pulled apart, it returns what it had, no more.
  EXPECT_FLOAT_EQ(solveBodyContact(far, c, 1e-4f, {0.0f, 0.0f}).dLambda, -1e-4f);
  // All kinematic: nothing moves.
  std::array<Point, 4> fixed = x;
  for (Point& p : fixed) p.w = 0.0f;
  EXPECT_EQ(solveBodyContact(fixed, c, 0.0f, {0.0f, 0.0f}).dLambda, 0.0f);
}

TEST(BodyContactProjection, FrictionSticksInsideTheConeAndSlidesOnItsEdge) {
  const Vec3 p0(0.3f, 0.002f, -0.2f);
  const std::array<Vec3, 4> x0{p0, kA, kB, kC};
  const std::array<Point, 4> x{Point{p0 + Vec3(0.001f, 0.0f, 0.0f), 1.0f}, Point{kA, 1.0f}, Point{kB, 1.0f},
                               Point{kC, 1.0f}};  // the vertex slid 1 mm along x
  const auto touch = touchVertexTriangle(p0, kA, kB, kC, true);
  ASSERT_TRUE(touch);
  const BodyContact c = contactOf(*touch, 0.002f, 0.5f);
  float inverseMass = 0.0f;
  for (float w : c.weight) inverseMass += w * w;
  // lambda_n large: sticks, the relative tangential motion cancelled exactly.
  const Vec3 stick = bodyContactFriction(x, x0, c, 1.0f, Vec3::Zero());
  EXPECT_NEAR((stick * inverseMass + Vec3(0.001f, 0.0f, 0.0f)).norm(), 0.0f, 1e-7f);  // a few ulp(0.3)
  // lambda_n small: slides, the friction multiplier on the dynamic cone mu_k lambda_n.
  const Vec3 slide = bodyContactFriction(x, x0, c, 1e-4f, Vec3::Zero());
  EXPECT_NEAR(slide.norm(), 0.5f * 1e-4f, 1e-9f);
  EXPECT_LT(slide.x(), 0.0f);
}

// Triangles of their own corners (none shared) with random boxes: each triangle spans its box's
// diagonal, the rest shape is where they are.
struct LooseTriangles {
  std::vector<Triangle> triangles;
  std::vector<Vec3> rest;
  std::vector<Box3f> boxes;
};
LooseTriangles randomTriangles(std::mt19937& rng, int count) {
  std::uniform_real_distribution<float> at(-1.0f, 1.0f), size(0.0f, 0.2f);
  LooseTriangles s;
  for (int k = 0; k < count; ++k) {
    const Vec3 lo(at(rng), at(rng), at(rng)), hi = lo + Vec3(size(rng), size(rng), size(rng));
    s.triangles.push_back({Index(3 * k), Index(3 * k + 1), Index(3 * k + 2)});
    s.rest.insert(s.rest.end(), {lo, hi, Vec3(lo.x(), hi.y(), lo.z())});
    s.boxes.emplace_back(lo, hi);
  }
  return s;
}

// The whole tree, part by part, as a team's members share it.
void refit(SurfaceTree& tree, const SurfaceFrame& frame) {
  for (std::size_t p = 0; p < tree.parts(); ++p) tree.refitPart(p, frame);
}
template <typename Visit>
void pairsOf(const SurfaceTree& a, const SurfaceTree& b, Visit&& visit) {
  for (std::size_t i = 0; i < a.parts(); ++i)
    for (std::size_t j = 0; j < b.parts(); ++j) a.pairsWith(b, i, j, visit);
}
template <typename Visit>
void selfPairsOf(const SurfaceTree& tree, bool closed, Visit&& visit) {
  for (std::size_t i = 0; i < tree.parts(); ++i)
    for (std::size_t j = i; j < tree.parts(); ++j) tree.selfPairs(closed, i, j, visit);
}

TEST(SurfaceTree, PairsOfTwoTreesAreEveryOverlappingPairOnce) {
  std::mt19937 rng(7);
  const LooseTriangles a = randomTriangles(rng, 300), b = randomTriangles(rng, 200);
  const std::vector<Vec3> up(300, Vec3::UnitZ());  // between two surfaces the cones play no part
  SurfaceTree ta, tb;
  ta.build(a.triangles, a.rest);
  tb.build(b.triangles, b.rest);
  ASSERT_EQ(ta.parts(), 8u);  // cut three levels down
  refit(ta, {a.boxes, up, up, {}});
  refit(tb, {b.boxes, std::span(up).first(200), std::span(up).first(200), {}});
  std::map<std::pair<Index, Index>, int> found;
  pairsOf(ta, tb, [&](Index t, Index u) { ++found[{t, u}]; });
  std::size_t overlapping = 0;
  for (Index t = 0; t < a.boxes.size(); ++t)
    for (Index u = 0; u < b.boxes.size(); ++u)
      if (a.boxes[t].intersects(b.boxes[u])) {
        ++overlapping;
        EXPECT_EQ((found[{t, u}]), 1) << t << ", " << u;
      }
  EXPECT_EQ(found.size(), overlapping);  // nothing that does not overlap
  EXPECT_GT(overlapping, 20u);
}

// Triangles that do not move (every corner kinematic) never touch each other: nodes of them alone
// are skipped, every overlapping pair with a moving triangle is still found once.
TEST(SurfaceTree, PairsOfTrianglesThatDoNotMoveAreSkipped) {
  std::mt19937 rng(5);
  const LooseTriangles a = randomTriangles(rng, 300), b = randomTriangles(rng, 300);
  const std::vector<Vec3> up(300, Vec3::UnitZ());
  std::vector<std::uint8_t> movingA(300, 0), movingB(300, 0);
  for (std::size_t t = 0; t < 300; ++t) movingA[t] = a.rest[3 * t].x() > 0.5f ? 1 : 0;  // a patch of a moves
  SurfaceTree ta, tb;
  ta.build(a.triangles, a.rest);
  tb.build(b.triangles, b.rest);
  refit(ta, {a.boxes, up, up, movingA});
  refit(tb, {b.boxes, up, up, movingB});
  std::map<std::pair<Index, Index>, int> found;
  pairsOf(ta, tb, [&](Index t, Index u) { ++found[{t, u}]; });
  std::size_t moving = 0, still = 0;
  for (Index t = 0; t < 300; ++t)
    for (Index u = 0; u < 300; ++u) {
      if (!a.boxes[t].intersects(b.boxes[u])) continue;
      if (movingA[t]) {
        ++moving;
        EXPECT_EQ((found[{t, u}]), 1) << t << ", " << u;
      } else {
        still += found.count({t, u});
      }
    }
  EXPECT_GT(moving, 5u);
  EXPECT_LT(still, moving);  // only where a leaf mixes moving and still triangles
  std::size_t none = 0;
  pairsOf(tb, tb, [&](Index, Index) { ++none; });
  selfPairsOf(tb, false, [&](Index, Index) { ++none; });
  EXPECT_EQ(none, 0u);
}

TEST(SurfaceTree, SelfPairsWithoutAFlatPatchAreEveryOverlappingPairOnce) {
  std::mt19937 rng(11);
  const LooseTriangles s = randomTriangles(rng, 400);
  const std::vector<Vec3> normals(s.boxes.size(), Vec3::Zero());  // degenerate: no cone faces one way
  SurfaceTree tree;
  tree.build(s.triangles, s.rest);
  refit(tree, {s.boxes, normals, normals, {}});
  for (const bool closed : {false, true}) {
    std::map<std::pair<Index, Index>, int> found;
    selfPairsOf(tree, closed, [&](Index t, Index u) { ++found[{std::min(t, u), std::max(t, u)}]; });
    std::size_t overlapping = 0;
    for (Index t = 0; t < s.boxes.size(); ++t)
      for (Index u = t + 1; u < s.boxes.size(); ++u)
        if (s.boxes[t].intersects(s.boxes[u])) {
          ++overlapping;
          EXPECT_EQ((found[{t, u}]), 1) << t << ", " << u;
        }
    EXPECT_EQ(found.size(), overlapping);
  }
}

// Two sheets of 2 x n x n triangles 1 mm apart (boxes grown by a skin), side by side at rest: the
// upper sheet facing down onto the lower (`fold`, as a fold brings them), or facing up as the
// lower does (two sheets stacked the same way up).
struct Layers {
  std::vector<Triangle> triangles;
  std::vector<Vec3> rest;
  std::vector<Box3f> boxes;
  std::vector<Vec3> normals;
  std::vector<int> layer;
};
Layers twoLayers(bool fold) {
  constexpr int n = 16;
  Layers s;
  for (int i = 0; i <= 2 * n + 1; ++i)  // columns n and n + 1 both at x = n: the sheets' edges
    for (int j = 0; j <= n; ++j) s.rest.emplace_back(float(i - (i > n ? 1 : 0)) / n, float(j) / n, 0.0f);
  const auto corner = [&](int i, int j) { return Index(i * (n + 1) + j); };
  for (int i = 0; i <= 2 * n; ++i)
    for (int j = 0; j < n; ++j) {
      if (i == n) continue;                                            // between the sheets
      const int side = i < n ? 0 : 1, at = side == 0 ? i : 2 * n - i;  // the upper sheet's x, folded over
      const Vec3 lo(float(at) / n, float(j) / n, side * 0.001f - 0.0006f);
      for (const Triangle& t : {Triangle{corner(i, j), corner(i + 1, j), corner(i + 1, j + 1)},
                                Triangle{corner(i, j), corner(i + 1, j + 1), corner(i, j + 1)}}) {
        s.triangles.push_back(t);
        s.boxes.emplace_back(lo, lo + Vec3(1.0f / n, 1.0f / n, 0.0012f));
        s.normals.push_back(Vec3(0.0f, 0.0f, side == 1 && fold ? -1.0f : 1.0f));
        s.layer.push_back(side);
      }
    }
  return s;
}

std::size_t overlapsAcross(const Layers& s) {
  std::size_t count = 0;
  for (std::size_t t = 0; t < s.boxes.size(); ++t)
    for (std::size_t u = 0; u < s.boxes.size(); ++u)
      count += s.layer[t] == 0 && s.layer[u] == 1 && s.boxes[t].intersects(s.boxes[u]) ? 1 : 0;
  return count;
}

SurfaceTree treeOf(const Layers& s) {
  SurfaceTree tree;
  tree.build(s.triangles, s.rest);
  refit(tree, {s.boxes, s.normals, s.normals, {}});
  return tree;
}

TEST(SurfaceTree, SelfPairsSkipPatchesThatFaceOneWayAndFindAFold) {
  const Layers s = twoLayers(true);
  const SurfaceTree tree = treeOf(s);
  std::size_t within = 0, across = 0;
  selfPairsOf(tree, true, [&](Index t, Index u) { ++(s.layer[t] == s.layer[u] ? within : across); });
  EXPECT_EQ(within, 0u);  // each sheet faces one way
  EXPECT_EQ(across, overlapsAcross(s));
  EXPECT_GT(across, 0u);
}

// Closed surfaces facing the same way cannot touch from outside (one would be inside the other's
// solid); a cloth's sheets can.
TEST(SurfaceTree, SheetsFacingTheSameWayMeetOnlyWhenTheyAreCloth) {
  const Layers s = twoLayers(false);
  const SurfaceTree tree = treeOf(s);
  std::size_t closed = 0, cloth = 0;
  selfPairsOf(tree, true, [&](Index, Index) { ++closed; });
  selfPairsOf(tree, false, [&](Index t, Index u) { cloth += s.layer[t] != s.layer[u] ? 1 : 0; });
  EXPECT_EQ(closed, 0u);
  EXPECT_EQ(cloth, overlapsAcross(s));
}

// The cone about the normals' mean direction.
NormalCone coneOf(std::span<const Vec3> normals) {
  std::vector<Index> all(normals.size());
  std::iota(all.begin(), all.end(), Index{0});
  Vec3 sum = Vec3::Zero();
  for (const Vec3& n : normals) sum += n;
  return coneAbout(sum.normalized(), all, normals, normals);
}

TEST(NormalCone, AnEnclosingConeHoldsEveryNormalOfBoth) {
  std::mt19937 rng(3);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> angle(0.0f, 1.5f);
  const auto inside = [](const NormalCone& c, const Vec3& n) {
    return std::acos(std::clamp(c.axis.dot(n), -1.0f, 1.0f)) <= std::acos(c.cos) + 1e-4f;
  };
  for (int k = 0; k < 500; ++k) {
    // Each cone's rim: a normal at its angle from the axis, in a random direction.
    std::array<NormalCone, 2> c;
    std::array<Vec3, 2> rim;
    const float equal = angle(rng);
    for (int s = 0; s < 2; ++s) {
      const float a = k % 2 == 0 ? equal : angle(rng);
      c[s] = {Vec3(g(rng), g(rng), g(rng)).normalized(), std::cos(a), std::sin(a)};
      const Vec3 across = c[s].axis.cross(Vec3(g(rng), g(rng), g(rng))).normalized();
      rim[s] = c[s].cos * c[s].axis + c[s].sin * across;
    }
    // About the bisector of the axes, and about any axis.
    const NormalCone m = enclosing((c[0].axis + c[1].axis).normalized(), c[0], c[1]);
    const NormalCone any = enclosing(Vec3(g(rng), g(rng), g(rng)).normalized(), c[0], c[1]);
    for (const NormalCone& e : {m, any}) {
      for (int s = 0; s < 2; ++s) {
        EXPECT_TRUE(inside(e, c[s].axis)) << k;
        EXPECT_TRUE(inside(e, rim[s])) << k;
      }
      EXPECT_NEAR(e.cos * e.cos + e.sin * e.sin, 1.0f, 1e-5f);
      EXPECT_GE(e.sin, 0.0f);
      EXPECT_TRUE(!facesOneWay(e) || faceOneWay(c[0], c[1])) << k;  // never narrower than both
    }
    // Two cones of one angle: the bisector is the narrowest axis, the same test as the pair's.
    if (k % 2 == 0) {
      EXPECT_EQ(faceOneWay(c[0], c[1]), facesOneWay(m)) << k;
    }
  }
  const auto one = [](const Vec3& n) { return coneOf(std::span(&n, 1)); };
  EXPECT_FALSE(faceOneWay(one(Vec3::UnitZ()), one(-Vec3::UnitZ())));  // opposite faces
  EXPECT_TRUE(faceOneWay(one(Vec3::UnitZ()), one(Vec3::UnitX())));    // a convex edge
  // A cube's corner faces one way; with a face turned against it (a corner pressing into a face) not.
  const std::vector<Vec3> corner{Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  EXPECT_TRUE(facesOneWay(coneOf(corner)));
  EXPECT_NEAR(coneOf(corner).cos, 1.0f / std::sqrt(3.0f), 1e-6f);
  EXPECT_FALSE(faceOneWay(coneOf(corner), one(-Vec3(1.0f, 1.0f, 1.0f).normalized())));
  // Degenerate: open.
  EXPECT_FALSE(facesOneWay(one(Vec3(0.0f, std::nanf(""), 0.0f))));
  const std::vector<Vec3> withNaN{Vec3::UnitX(), Vec3(std::nanf(""), 0.0f, 0.0f)};
  const std::vector<Index> both{0, 1};
  EXPECT_EQ(coneAbout(Vec3::UnitX(), both, withNaN, withNaN).cos, -1.0f);
  const std::vector<Vec3> withZero{Vec3::UnitX(), Vec3::Zero()};
  EXPECT_FALSE(facesOneWay(coneAbout(Vec3::UnitX(), both, withZero, withZero)));
}

}  // namespace
}  // namespace vrd
