#pragma once
// Area-weighted vertex normals of a triangle surface.

#include <span>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Unit normals at the vertices of `triangles` over `positions`, each the area-weighted mean of its
/// triangles' normals (summed in double); zero for a vertex in no triangle or whose triangle normals
/// cancel. Throws vrd::Error for an out-of-range index or spans of different sizes.
void computeVertexNormals(std::span<const Triangle> triangles, std::span<const Vec3> positions,
                          std::span<Vec3> outNormals);

}  // namespace vrd
