// Cloth from the flag generator and from any open surface: a distance constraint per edge, a
// bending constraint per interior edge, and a pinned edge that holds while the rest hangs.
#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/body_model.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

Material clothMaterial() {
  Material m;
  m.particleMass = 0.002f;
  m.distance = {1e-6f, 0.0f};
  m.bending = {0.5f, 0.0f};
  return m;
}

// Hangs a cloth with the given vertices pinned for `seconds`, with a constant force per particle
// (wind); returns the world positions.
std::vector<Vec3> hang(const TriMesh& cloth, const std::vector<Index>& pinned, float seconds,
                       const Vec3& wind = Vec3::Zero(), float damping = 0.0f) {
  SolverSettings settings;
  settings.substeps = 8;
  settings.linearDamping = damping;
  World world(settings);
  const BodyId b = world.addBody(makeCloth(cloth, clothMaterial()));
  for (Index v : pinned) world.setInverseMass(world.particleIndex(b, v), 0.0f);
  world.setExternalForce(b, wind);
  for (int s = 0; s < int(seconds / settings.timeStep); ++s) world.step();
  std::vector<Vec3> x;
  for (Index v = 0; v < cloth.vertices.size(); ++v) x.push_back(world.particles().x[world.particleIndex(b, v)].pos);
  return x;
}

TEST(Cloth, FlagHasItsPoleEdgePinnedAndABendPerInteriorEdge) {
  const int nu = 12, nv = 8;
  const Flag flag = makeFlag(Vec3(0, 2, 0), 0.6f, 0.4f, nu, nv);
  ASSERT_EQ(flag.pinned.size(), std::size_t(nv + 1));
  for (Index v : flag.pinned) EXPECT_EQ(flag.cloth.vertices[v].x(), 0.0f);
  const auto model = makeCloth(flag.cloth, clothMaterial());
  // Edges: nu(nv+1) horizontal + nv(nu+1) vertical + nu*nv diagonals; 2(nu+nv) on the border.
  const std::size_t edges = nu * (nv + 1) + nv * (nu + 1) + nu * nv;
  EXPECT_EQ(model->distance.size(), edges);
  EXPECT_EQ(model->bend.size(), edges - 2 * (nu + nv));
}

TEST(Cloth, FlagBillowsInTheWindFromItsPole) {
  // In its own plane the triangulated flag is a rigid truss, and gravity has no torque about the
  // vertical pole; a steady wind across it (+z) turns it about the pole until it streams
  // downwind (damped, so it settles instead of swinging on).
  const Flag flag = makeFlag(Vec3(0, 2, 0), 0.6f, 0.4f, 12, 8);
  const float weight = *clothMaterial().particleMass * 9.81f;
  const std::vector<Vec3> x = hang(flag.cloth, flag.pinned, 4.0f, Vec3(0, 0, weight), 3.0f);
  for (Index v : flag.pinned) EXPECT_EQ(x[v], flag.cloth.vertices[v]);
  const Index farTop = 12;  // (iu, iv) = (12, 0)
  const Vec3 arm = x[farTop] - x[0];
  EXPECT_NEAR(arm.norm(), 0.6f, 0.01f);  // edges barely stretch
  EXPECT_GT(arm.z(), 0.55f);             // streams downwind
  EXPECT_LT(std::abs(arm.x()), 0.15f);
  for (const Vec3& p : x) EXPECT_TRUE(isFinite(p));
}

TEST(Cloth, AnyOpenSurfaceBecomesCloth) {
  // The shared flag: an irregular 1.25 m square in the y = 0 plane, 2,440 edges, 80 on the border.
  const TriMesh flag = readSurface(testing::kMeshes / "flag_plane.obj");
  const auto model = makeCloth(flag, clothMaterial());
  EXPECT_EQ(model->distance.size(), 2440u);
  EXPECT_EQ(model->bend.size(), 2440u - 80u);
  // Pin the edge at x = -0.625 and let it drape.
  std::vector<Index> pinned;
  for (Index v = 0; v < flag.vertices.size(); ++v)
    if (flag.vertices[v].x() < -0.625f + 1e-4f) pinned.push_back(v);
  ASSERT_GE(pinned.size(), 10u);
  const std::vector<Vec3> x = hang(flag, pinned, 1.5f);
  float lowest = 0;
  for (const Vec3& p : x) {
    ASSERT_TRUE(isFinite(p));
    lowest = std::min(lowest, p.y());
  }
  EXPECT_LT(lowest, -0.8f);           // the far edge has swung down...
  EXPECT_GT(lowest, -1.25f * 1.02f);  // ...no further than the cloth is long
}

}  // namespace
}  // namespace vrd
