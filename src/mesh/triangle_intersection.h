#pragma once
// Intersection tests between closed triangles in double, for the surface self-intersection check.
// A point within `tol` of a plane counts as on it, so nearly coplanar float input is handled as
// coplanar instead of by rounding noise; decisions within a plane are plain sign tests, so near
// misses are not turned into contacts.

#include <array>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

using Triangle3d = std::array<Vec3d, 3>;

/// A distance tolerance for a pair of triangles: a millionth of their longest edge plus two float
/// ulps of their largest coordinate (float input is flat only to that precision).
double intersectionTolerance(const Triangle3d& p, const Triangle3d& q);

/// Whether the closed segment ab meets the closed, non-degenerate triangle t (touching counts).
bool segmentIntersectsTriangle(const Vec3d& a, const Vec3d& b, const Triangle3d& t, double tol);

/// Whether closed, non-degenerate triangles p and q meet (touching counts): after the plane-side
/// rejection of Möller's method, whether an edge of one meets the other (in 2D when coplanar).
bool trianglesIntersect(const Triangle3d& p, const Triangle3d& q, double tol);

/// Whether mesh faces p and q (vertex ids pIds, qIds) meet anywhere beyond what they share:
/// faces with a common edge only when folded flat onto each other, faces with a common vertex
/// when the edge opposite it in one meets the other; faces on the same three vertices always.
bool facesIntersect(const Triangle3d& p, const Triangle& pIds, const Triangle3d& q, const Triangle& qIds, double tol);

}  // namespace vrd
