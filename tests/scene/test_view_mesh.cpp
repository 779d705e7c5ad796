// What viewers draw of each body (scene/view_mesh.h): the render mesh through its embedding, a
// soft body's boundary, a cloth's triangles; all following the simulated particles.

#include <gtest/gtest.h>

#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/view_mesh.h"

namespace vrd {
namespace {

BuiltScene quickScene(const std::string& name) {
  SceneSpec spec = loadSceneByName(name);
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  return buildScene(spec);
}

Snapshot snapshotOf(const World& world) {
  Snapshot s;
  for (const Point& p : world.particles().x) s.positions.push_back(p.pos);
  for (BodyId b = 0; b < world.bodyCount(); ++b) s.bodyFirst.push_back(world.body(b).firstParticle);
  return s;
}

TEST(ViewMesh, SoftBodyShowsItsBoundaryAtTheParticles) {
  const BuiltScene scene = quickScene("furball");  // no render mesh
  const std::vector<ViewMesh> meshes = viewMeshes(scene);
  ASSERT_EQ(meshes.size(), 1u);
  const ViewMesh& m = meshes[0];
  EXPECT_EQ(m.embedding, nullptr);
  EXPECT_EQ(m.triangles.size(), boundaryFaces(scene.bodies[0].mesh.tets).size());
  EXPECT_LT(m.vertexCount(), scene.bodies[0].mesh.tets.vertices.size());  // interior vertices left out

  const Snapshot s = snapshotOf(*scene.world);
  std::vector<Vec3> pos(m.vertexCount()), nrm(m.vertexCount());
  updateViewMesh(m, bodyPositions(s, 0), pos, nrm);
  for (std::size_t v = 0; v < pos.size(); ++v) {
    EXPECT_EQ(pos[v], s.positions[m.particles[v]]);
    EXPECT_NEAR(nrm[v].norm(), 1.0f, 1e-5f);
  }
  // Outward normals: on average they point away from the centroid.
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : pos) centre += p / float(pos.size());
  double outward = 0;
  for (std::size_t v = 0; v < pos.size(); ++v) outward += nrm[v].dot((pos[v] - centre).normalized());
  EXPECT_GT(outward / double(pos.size()), 0.5);
}

TEST(ViewMesh, RenderMeshFollowsTheTets) {
  BuiltScene scene = quickScene("bear");
  const std::vector<ViewMesh> meshes = viewMeshes(scene);
  ASSERT_NE(meshes[0].embedding, nullptr);
  EXPECT_EQ(meshes[0].triangles.size(), scene.bodies[0].mesh.render.triangles.size());
  // Translate every particle: every render vertex moves by the same amount.
  Snapshot s = snapshotOf(*scene.world);
  std::vector<Vec3> before(meshes[0].vertexCount()), after(before.size());
  updateViewMesh(meshes[0], bodyPositions(s, 0), before, {});
  const Vec3 shift(0.1f, -0.2f, 0.3f);
  for (Vec3& p : s.positions) p += shift;
  updateViewMesh(meshes[0], bodyPositions(s, 0), after, {});
  for (std::size_t v = 0; v < before.size(); ++v) EXPECT_LT((after[v] - before[v] - shift).norm(), 1e-5f);
}

TEST(ViewMesh, ClothShowsItsTrianglesAndWrongSizesAreRefused) {
  const BuiltScene scene = quickScene("flag");
  const std::vector<ViewMesh> meshes = viewMeshes(scene);
  const ViewMesh& m = meshes[0];
  EXPECT_EQ(m.kind, BodyKind::Cloth);
  EXPECT_EQ(m.triangles.size(), scene.bodies[0].mesh.surface.triangles.size());
  const Snapshot s = snapshotOf(*scene.world);
  std::vector<Vec3> pos(m.vertexCount()), tooFew(m.vertexCount() - 1);
  EXPECT_NO_THROW(updateViewMesh(m, bodyPositions(s, 0), pos, {}));
  EXPECT_THROW(updateViewMesh(m, bodyPositions(s, 0), tooFew, {}), Error);
  EXPECT_THROW(updateViewMesh(m, bodyPositions(s, 0).first(3), pos, {}), Error);
  EXPECT_THROW(bodyPositions(s, 1), Error);
}

}  // namespace
}  // namespace vrd
