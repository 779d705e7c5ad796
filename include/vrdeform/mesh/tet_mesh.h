#pragma once
// Tetrahedral and triangle meshes as plain vertex + element arrays, and their validity checks.

#include <array>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

using Tet = std::array<Index, 4>;
using Triangle = std::array<Index, 3>;

/// A tetrahedral mesh. A tet (a, b, c, d) is positively oriented when (b-a).((c-a)x(d-a)) > 0.
struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<Tet> tets;
};

/// A triangle mesh (a cloth, or a surface).
struct TriMesh {
  std::vector<Vec3> vertices;
  std::vector<Triangle> triangles;
};

/// Eq. 16: signed volume of the tet (p1, p2, p3, p4), positive for positive orientation.
template <typename S>
S signedTetVolume(const Vec3T<S>& p1, const Vec3T<S>& p2, const Vec3T<S>& p3, const Vec3T<S>& p4) {
  return (p2 - p1).cross(p3 - p1).dot(p4 - p1) / S(6);
}

/// Relative size below which a rest element counts as degenerate: 6|V| / l_max^3 for tets,
/// 2A / l_max^2 for triangles. A regular tet scores 0.71; a 5-degree sliver still scores ~0.05.
inline constexpr double kDegenerateShape = 1e-6;

/// Throws vrd::Error naming the first offending element when the mesh has no elements, a
/// non-finite coordinate, an out-of-range or repeated index, or a degenerate or inverted tet.
void validateTetMesh(const TetMesh& mesh);

/// Drops the vertices no tet uses (tet files may list some; a body cannot have them), keeping the
/// others in order, and renumbers the tets. Returns how many were dropped; throws vrd::Error for
/// an index out of range.
std::size_t removeUnusedVertices(TetMesh& mesh);

/// Throws vrd::Error for an empty mesh, non-finite coordinates, bad indices or degenerate triangles.
void validateTriMesh(const TriMesh& mesh);

}  // namespace vrd
