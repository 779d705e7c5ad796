// Body contact's pieces (sim/body_contact.h, sim/spatial_hash.h): the contact plane of a vertex and
// a triangle, one projection and its friction, and the broad phase's hash, each against geometry
// worked out by hand.

#include <gtest/gtest.h>

#include <random>

#include "vrdeform/sim/body_contact.h"
#include "vrdeform/sim/spatial_hash.h"

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

TEST(SpatialHash, QueriesFindEveryOverlappingBox) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> at(-1.0f, 1.0f), size(0.0f, 0.2f);
  std::vector<Box3f> boxes;
  for (int k = 0; k < 500; ++k) {
    const Vec3 lo(at(rng), at(rng), at(rng));
    boxes.emplace_back(lo, lo + Vec3(size(rng), size(rng), size(rng)));
  }
  const float inf = std::numeric_limits<float>::infinity();
  boxes.emplace_back(Vec3(-inf, 0.0f, 0.0f), Vec3(inf, 0.0f, 0.0f));      // unbounded: on the list
  boxes.emplace_back(Vec3(-5.0f, -5.0f, -5.0f), Vec3(5.0f, 5.0f, 5.0f));  // too many cells: on the list
  SpatialHash hash;
  hash.build(boxes, 0.1f);
  for (int q = 0; q < 200; ++q) {
    const Vec3 lo(at(rng), at(rng), at(rng));
    const Box3f box(lo, lo + Vec3(size(rng), size(rng), size(rng)));
    std::vector<char> found(boxes.size(), 0);
    hash.query(box, [&](Index item) { found[item] = 1; });
    for (std::size_t k = 0; k < boxes.size(); ++k)
      EXPECT_TRUE(found[k] || !boxes[k].intersects(box)) << "box " << k << " missed by query " << q;
  }
}

}  // namespace
}  // namespace vrd
