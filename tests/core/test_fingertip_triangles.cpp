// Fingertips against a body's surface triangles (FingertipContactMode::Triangles, beyond the
// paper's particle contacts of eqs. 36-39): the projection itself, a fingertip pressing between
// the vertices of a coarse mesh, the momentum balance of docs/validation.md V12a, disabling, cloth,
// and bad surface indices.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

#include "block_on_ground.h"
#include "test_support.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using testing::errorOf;

using testing::kG;

// --- The projection ----------------------------------------------------------------------------

TEST(FingertipTriangles, ProjectionFollowsEq38WithTheBarycentricWeights) {
  // Centre above the centroid, 1 cm too close: b = (1/3, 1/3, 1/3), sum_k b_k^2 w_k = 1/3.
  const Point x0{Vec3(0, 0, 0), 1.0f}, x1{Vec3(0.3f, 0, 0), 1.0f}, x2{Vec3(0, 0, 0.3f), 1.0f};
  const Vec3 centroid(0.1f, 0.0f, 0.1f), centre = centroid - Vec3(0.0f, 0.04f, 0.0f);  // below: n = -y
  const float r = 0.05f, alphaTilde = 2.0f;
  const XpbdCoefficients k{alphaTilde, 0.0f};
  const TriangleContactCorrection c = solveFingertipTriangleContact(x0, x1, x2, centre, r, 0.0f, k);
  EXPECT_NEAR(c.dLambda, 0.01f / (1.0f / 3.0f + alphaTilde), 1e-6f);
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(c.grad[k].isApprox(Vec3(0.0f, 1.0f / 3.0f, 0.0f), 1e-5f));  // -b_k n
    EXPECT_TRUE(c.dp[k].isApprox(Vec3(0.0f, c.dLambda / 3.0f, 0.0f), 1e-5f));
  }

  // Zero compliance, equal masses, closest point at the centroid: the triangle translates along n
  // by exactly -C, so one projection satisfies the constraint.
  const TriangleContactCorrection hard = solveFingertipTriangleContact(x0, x1, x2, centre, r, 0.0f, {0.0f, 0.0f});
  const auto after =
      evalFingertipTriangleContact<float>(x0.pos + hard.dp[0], x1.pos + hard.dp[1], x2.pos + hard.dp[2], centre, r);
  EXPECT_NEAR(after.C, 0.0f, 1e-6f);

  // Inequality: separated, the accumulated lambda only falls back to 0.
  const Vec3 clear = centroid - Vec3(0.0f, 0.2f, 0.0f);
  EXPECT_EQ(solveFingertipTriangleContact(x0, x1, x2, clear, r, 0.0f, k).dLambda, 0.0f);
  EXPECT_NEAR(solveFingertipTriangleContact(x0, x1, x2, clear, r, 1e-3f, {0.0f, 0.0f}).dLambda, -1e-3f, 1e-9f);
}

TEST(FingertipTriangles, KinematicAndDegenerateTrianglesDoNothing) {
  const Vec3 a(0, 0, 0), b(0.3f, 0, 0), c(0, 0, 0.3f), centre(0.1f, 0.02f, 0.1f);
  const XpbdCoefficients soft{1.0f, 0.0f};  // compliant: a zero denominator is not what stops it
  auto isNothing = [](const TriangleContactCorrection& r) {
    return r.dLambda == 0.0f && r.dp[0].isZero() && r.dp[1].isZero() && r.dp[2].isZero();
  };
  EXPECT_TRUE(isNothing(solveFingertipTriangleContact({a, 0.0f}, {b, 0.0f}, {c, 0.0f}, centre, 0.05f, 0.0f, soft)));
  // Closest point at corner a, which is kinematic: sum_k b_k^2 w_k = 0.
  EXPECT_TRUE(isNothing(
      solveFingertipTriangleContact({a, 0.0f}, {b, 1.0f}, {c, 1.0f}, Vec3(-0.01f, 0.01f, -0.01f), 0.05f, 0.0f, soft)));
  // Zero area: c on the edge a-b.
  EXPECT_TRUE(
      isNothing(solveFingertipTriangleContact({a, 1.0f}, {b, 1.0f}, {0.5f * b, 1.0f}, centre, 0.05f, 0.0f, soft)));
}

// --- A block on the ground ---------------------------------------------------------------------

// The V12 block (block_on_ground.h) with what these tests read off its surface.
struct SurfaceBlock : testing::BlockOnGround {
  using testing::BlockOnGround::BlockOnGround;
  // Centroid, now, of the first surface triangle in the top face (the block sags under its weight).
  Vec3 topTriangleCentroid() const {
    const BodyModel& m = *world.body(body).model;
    for (const Triangle& t : m.surface)
      if (std::all_of(t.begin(), t.end(), [&](Index v) { return m.restPositions[v].y() == size; }))
        return (position(t[0]) + position(t[1]) + position(t[2])) / 3.0f;
    ADD_FAILURE() << "no top face";
    return Vec3::Zero();
  }
  void settle() {
    for (int step = 0; step < 60; ++step) world.step();
  }
  // Distance from p to the body's surface (its nearest surface triangle), now; in double.
  double surfaceDistance(const Vec3& p) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Triangle& t : world.body(body).model->surface) {
      const auto e = evalFingertipTriangleContact<double>(position(t[0]).cast<double>(), position(t[1]).cast<double>(),
                                                          position(t[2]).cast<double>(), p.cast<double>(), 0.0);
      best = std::min(best, e.C);
    }
    return best;
  }
};

// Moves the fingertip from `from` to `to` in `steps` equal steps, calling check() after each.
template <typename Check>
void press(World& world, FingertipId tip, const Vec3& from, const Vec3& to, int steps, Check&& check) {
  for (int s = 1; s <= steps; ++s) {
    world.moveFingertip(tip, from + (to - from) * (float(s) / float(steps)));
    world.step();
    check();
  }
}

constexpr float kCoarseSide = 0.2f;  // 2 x 2 x 2 cells of 10 cm
constexpr int kCoarseCells = 2;
constexpr float kSmallRadius = 0.01f;  // the nearest vertex is 4.7 cm from a top triangle's centroid

TEST(FingertipTriangles, ParticlesModePassesBetweenTheVerticesOfACoarseFace) {
  SurfaceBlock block(kCoarseSide, kCoarseCells), reference(kCoarseSide, kCoarseCells);
  block.settle();
  reference.settle();
  const Vec3 centroid = block.topTriangleCentroid();
  const Vec3 above = centroid + Vec3(0.0f, 2.0f * kSmallRadius, 0.0f);
  const FingertipId tip = block.world.addFingertip(above, kSmallRadius);  // Particles, the paper's contacts
  ASSERT_EQ(block.world.fingertip(tip).mode, FingertipContactMode::Particles);
  const Vec3 inside = centroid - Vec3(0.0f, 5.0f * kSmallRadius, 0.0f);  // 4 cm below the face
  press(block.world, tip, above, inside, 60, [&] {
    reference.world.step();
    EXPECT_EQ(block.world.fingertipContactCount(tip), 0u);
    EXPECT_EQ(block.world.lastStep().fingertipContacts, 0u);
    EXPECT_TRUE(block.world.fingertipForce(tip).isZero());
  });
  // The sphere sank through the face into the block, which never noticed it.
  EXPECT_LT(block.world.fingertip(tip).center.y(), kCoarseSide - 2.0f * kSmallRadius);
  for (std::size_t i = 0; i < block.world.particles().size(); ++i)
    EXPECT_EQ(block.world.particles().x[i].pos, reference.world.particles().x[i].pos) << "particle " << i;
}

TEST(FingertipTriangles, TrianglesModePushesTheFaceBetweenVertices) {
  const int substeps = 4;
  SurfaceBlock block(kCoarseSide, kCoarseCells, substeps);
  block.settle();
  const Vec3 centroid = block.topTriangleCentroid();
  const Vec3 above = centroid + Vec3(0.0f, 2.0f * kSmallRadius, 0.0f);
  const FingertipId tip = block.world.addFingertip(above, kSmallRadius, 0.0f, FingertipContactMode::Triangles);

  // 5 mm into the face over 30 steps, then held for 200.
  const float depth = 0.5f * kSmallRadius;
  const Vec3 pressed = centroid + Vec3(0.0f, kSmallRadius - depth, 0.0f);
  const int pressSteps = 30;
  // Tolerance: the fingertip projection comes last in every sweep, so what is left after the last
  // sweep is its own nonlinearity. A corner correction of size d tilts the triangle by ~d/L (L its
  // shortest edge, 10 cm), which moves the closest point by at most ~d^2/L; d is bounded by what
  // one substep's prediction brings into the sphere: g h^2 plus the fingertip's motion per
  // substep. Plus float rounding of 0.2 m coordinates (1.5e-8 m per ulp; 1e-6 m allows ~70 ulps).
  const float h = block.world.substepSize();
  const float perSubstep = kG * h * h + (2.0f * kSmallRadius + depth) / float(pressSteps * substeps);
  const double tolerance = double(perSubstep) * perSubstep / 0.1 + 1e-6;
  double worst = std::numeric_limits<double>::infinity();
  auto outside = [&] {
    const double d = block.surfaceDistance(block.world.fingertip(tip).center);
    worst = std::min(worst, d);
    EXPECT_GE(d, kSmallRadius - tolerance) << "step " << block.world.stepCount();
  };
  press(block.world, tip, above, pressed, pressSteps, outside);
  for (int step = 0; step < 200; ++step) {
    block.world.step();
    outside();
  }
  testing::record("worst_surface_distance_minus_radius_m", worst - kSmallRadius);
  testing::record("tolerance_m", tolerance);

  EXPECT_GT(block.world.fingertipContactCount(tip), 0u);
  EXPECT_GT(block.world.lastStep().fingertipContacts, 0u);
  EXPECT_FALSE(block.world.fingertipTriangleContacts().empty());
  EXPECT_EQ(block.world.fingertipTriangleContactLambda().size(), block.world.fingertipTriangleContacts().size());
  EXPECT_TRUE(block.world.fingertipContacts().empty());  // no particle contacts in Triangles mode
  EXPECT_GT(block.world.fingertipLambdaSum(tip), 0.0f);
  // The push points into the body (down, the top face's inward normal), and is what the ground
  // carries beyond the weight.
  const Vec3 push = block.world.fingertipForce(tip);
  testing::record("push_N", -push.y());
  EXPECT_LT(push.y(), 0.0f);
  EXPECT_LT(push.head<1>().norm() + std::abs(push.z()), 0.2f * -push.y());
  EXPECT_NEAR(-push.y(), block.groundReaction() - block.weight, 1e-3f * block.groundReaction());
}

TEST(FingertipTriangles, DisabledFingertipMakesNoContacts) {
  SurfaceBlock block(kCoarseSide, kCoarseCells);
  block.settle();
  const Vec3 centroid = block.topTriangleCentroid();
  const Vec3 pressed = centroid + Vec3(0.0f, 0.5f * kSmallRadius, 0.0f);  // 5 mm into the face
  const FingertipId tip = block.world.addFingertip(pressed, kSmallRadius, 0.0f, FingertipContactMode::Triangles);
  block.world.setFingertipEnabled(tip, false);
  for (int step = 0; step < 30; ++step) {
    block.world.step();
    EXPECT_TRUE(block.world.fingertipTriangleContacts().empty());
    EXPECT_EQ(block.world.fingertipContactCount(tip), 0u);
    EXPECT_EQ(block.world.lastStep().fingertipContacts, 0u);
    EXPECT_TRUE(block.world.fingertipForce(tip).isZero());
  }
  block.world.setFingertipEnabled(tip, true);
  for (int step = 0; step < 30; ++step) block.world.step();
  EXPECT_GT(block.world.fingertipContactCount(tip), 0u);
  EXPECT_LT(block.world.fingertipForce(tip).y(), 0.0f);
  // Back to the paper's particle contacts: between the vertices it touches nothing.
  block.world.setFingertipContactMode(tip, FingertipContactMode::Particles);
  block.world.step();
  EXPECT_TRUE(block.world.fingertipTriangleContacts().empty());
  EXPECT_EQ(block.world.fingertipContactCount(tip), 0u);
  EXPECT_THROW(block.world.setFingertipContactMode(tip, FingertipContactMode(7)), Error);
}

// --- Cloth ---------------------------------------------------------------------------------------

TEST(FingertipTriangles, PinnedClothDeflectsUnderAFingertipBetweenVertices) {
  // A 30 cm square of 3 x 3 cells (10 cm) in the y = 0 plane, pinned at its corners, no gravity;
  // a 2 cm fingertip comes down on the centroid of a middle triangle, 4.7 cm from its nearest
  // vertex, to 5 cm below the cloth's plane.
  Material m;
  m.particleMass = 0.002f;
  m.distance = {1e-6f, 0.0f};
  m.bending = {0.5f, 0.0f};
  const int n = 3;
  const auto cloth = makeCloth(makeGridCloth(Vec3(-0.15f, 0, -0.15f), Vec3(0.3f, 0, 0), Vec3(0, 0, 0.3f), n, n), m);
  const float r = 0.02f;
  const Vec3 centroid(0.05f - 0.1f / 3.0f, 0.0f, -0.05f + 0.1f / 3.0f);  // triangle (1,1), (2,1), (2,2)
  const Vec3 above = centroid + Vec3(0.0f, 1.5f * r, 0.0f), below = centroid - Vec3(0.0f, 0.05f - r, 0.0f);

  for (const FingertipContactMode mode : {FingertipContactMode::Particles, FingertipContactMode::Triangles}) {
    SolverSettings s;
    s.gravity.setZero();
    s.substeps = 8;
    s.linearDamping = 5.0f;
    World world(s);
    const BodyId b = world.addBody(cloth);
    ASSERT_EQ(cloth->surface.size(), cloth->triangles.size());
    for (Index corner : {Index(0), Index(n), Index(n * (n + 1)), Index((n + 1) * (n + 1) - 1)})
      world.setInverseMass(world.particleIndex(b, corner), 0.0f);
    const FingertipId tip = world.addFingertip(above, r, 0.0f, mode);
    press(world, tip, above, below, 60, [] {});
    for (int step = 0; step < 60; ++step) world.step();

    float lowest = 0.0f;
    for (Index v = 0; v < cloth->particleCount(); ++v)
      lowest = std::min(lowest, world.particles().x[world.particleIndex(b, v)].pos.y());
    const Vec3 force = world.fingertipForce(tip);
    if (mode == FingertipContactMode::Particles) {  // the sphere slips through the cell untouched
      EXPECT_EQ(lowest, 0.0f);
      EXPECT_TRUE(force.isZero());
    } else {  // the cloth wraps under the sphere, whose bottom is at y = -5 cm
      EXPECT_LT(lowest, -0.045f);
      EXPECT_GT(world.fingertipContactCount(tip), 0u);
      EXPECT_LT(force.y(), 0.0f);
      testing::record("cloth_push_N", -force.y());
    }
  }
}

// --- Bad input -----------------------------------------------------------------------------------

TEST(FingertipTriangles, SurfaceIndicesAreValidated) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 1, 1, 1);
  const auto good = makeSoftBody(mesh, Material{});
  EXPECT_EQ(good->surface.size(), 12u);  // two triangles per face of the cube
  BodyModel bad = *good;
  bad.surface.push_back({0, 1, 99});
  std::string msg = errorOf([&] { validateModel(bad); });
  EXPECT_NE(msg.find("surface triangle 12"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle 99"), std::string::npos) << msg;
  World world;
  EXPECT_FALSE(errorOf([&] { world.addBody(std::make_shared<BodyModel>(bad)); }).empty());
  EXPECT_EQ(world.bodyCount(), 0u);

  bad.surface.back() = {2, 5, 2};
  msg = errorOf([&] { validateModel(bad); });
  EXPECT_NE(msg.find("surface triangle 12"), std::string::npos) << msg;
  EXPECT_NE(msg.find("twice"), std::string::npos) << msg;
}

}  // namespace
}  // namespace vrd
