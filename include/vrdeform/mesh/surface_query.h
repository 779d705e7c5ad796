#pragma once
// Point-in-solid and segment-crossing queries against a closed triangle surface, over a BVH.
// The built-in mesher classifies lattice points and finds where lattice edges cross the surface.

#include <optional>

#include "vrdeform/mesh/bvh.h"
#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

class SurfaceQuery {
 public:
  /// Keeps a reference to `surface`, which must outlive the query and stay unchanged.
  explicit SurfaceQuery(const TriMesh& surface);

  /// Whether p is inside the closed surface: crossing parity of rays along +x, +y and +z, by
  /// majority, skipping a ray that grazes an edge or vertex.
  bool inside(const Vec3d& p) const;

  /// The crossing of segment a->b with the surface nearest to a, as a fraction of the way to b.
  std::optional<double> firstCrossing(const Vec3d& a, const Vec3d& b) const;

 private:
  /// Crossings of the ray p + t e_axis, t > 0; nullopt when the ray grazes an edge or vertex.
  std::optional<int> rayCrossings(const Vec3d& p, int axis) const;

  const TriMesh& surface_;
  Bvh bvh_;
  Box3d bounds_;
};

}  // namespace vrd
