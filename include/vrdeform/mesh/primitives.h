#pragma once
// Procedural meshes for tests, benchmarks and demos.

#include <vector>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Box [origin, origin + size] cut into nx*ny*nz cells of 6 positively oriented tets each
/// (Kuhn subdivision along each cell's main diagonal, so neighbouring cells share faces).
TetMesh makeBoxTets(const Vec3& origin, const Vec3& size, int nx, int ny, int nz);

/// A box of roughly `targetTets` tets (cell counts rounded, so coarse boxes may miss by more
/// than 10%) with cells as close to cubes as the aspect ratio of `size` allows.
TetMesh makeBoxTetsNear(const Vec3& origin, const Vec3& size, int targetTets);

/// A rectangular cloth in the plane spanned by `uAxis` and `vAxis` from `origin`, nu*nv quads split
/// into two triangles each; vertex (iu, iv) has index iv*(nu+1) + iu.
TriMesh makeGridCloth(const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis, int nu, int nv);

/// A latitude-longitude sphere surface: two poles and rings - 1 circles of `segments` vertices,
/// outward-facing triangles (a closed, fine render surface for tests and benchmarks).
TriMesh makeUvSphere(const Vec3& centre, float radius, int rings, int segments);

/// The paper's flag: a cloth of nu x nv cells hung on a vertical pole whose top is `poleTop`,
/// `width` along +x and `height` down -y. `pinned` lists the nv + 1 vertices on the pole.
struct Flag {
  TriMesh cloth;
  std::vector<Index> pinned;
};
Flag makeFlag(const Vec3& poleTop, float width, float height, int nu, int nv);

}  // namespace vrd
