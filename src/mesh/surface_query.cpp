#include "vrdeform/mesh/surface_query.h"

#include <vector>

namespace vrd {
namespace {

Vec3d corner(const TriMesh& mesh, const Triangle& t, int k) { return mesh.vertices[t[k]].cast<double>(); }

// Twice the signed area of (a, b, p) in the plane of coordinates (u, v).
double orient2d(const Vec3d& a, const Vec3d& b, const Vec3d& p, int u, int v) {
  return (b[u] - a[u]) * (p[v] - a[v]) - (b[v] - a[v]) * (p[u] - a[u]);
}

}  // namespace

SurfaceQuery::SurfaceQuery(const TriMesh& surface) : surface_(surface) {
  std::vector<Box3d> boxes(surface.triangles.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) boxes[t] = elementBox(surface.vertices, surface.triangles[t]);
  bvh_ = Bvh(boxes);
  for (const Box3d& b : boxes) bounds_.extend(b);
}

std::optional<int> SurfaceQuery::rayCrossings(const Vec3d& p, int axis) const {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  Vec3d far = p;
  far[axis] = std::max(p[axis], bounds_.max()[axis]) + 1.0;
  int crossings = 0;
  bool grazes = false;
  bvh_.overlapping(Box3d(p, far), [&](Index t) {
    const Triangle& tri = surface_.triangles[t];
    const Vec3d a = corner(surface_, tri, 0), b = corner(surface_, tri, 1), c = corner(surface_, tri, 2);
    const double wa = orient2d(b, c, p, u, v), wb = orient2d(c, a, p, u, v), wc = orient2d(a, b, p, u, v);
    const bool anyNegative = wa < 0 || wb < 0 || wc<0, anyPositive = wa> 0 || wb > 0 || wc > 0;
    if (anyNegative && anyPositive) return;  // the ray misses the projected triangle
    const double sum = wa + wb + wc;
    if (sum == 0 || wa == 0 || wb == 0 || wc == 0) {  // edge-on triangle, or the ray hits an edge
      grazes = true;
      return;
    }
    const double hit = (wa * a[axis] + wb * b[axis] + wc * c[axis]) / sum;
    if (hit > p[axis]) ++crossings;
  });
  if (grazes) return std::nullopt;
  return crossings;
}

bool SurfaceQuery::inside(const Vec3d& p) const {
  if (!bounds_.contains(p)) return false;
  int votesInside = 0, votes = 0;
  for (int axis = 0; axis < 3; ++axis)
    if (const auto crossings = rayCrossings(p, axis)) {
      ++votes;
      votesInside += *crossings % 2;
    }
  return 2 * votesInside > votes;
}

std::optional<double> SurfaceQuery::firstCrossing(const Vec3d& a, const Vec3d& b) const {
  Box3d box(a.cwiseMin(b), a.cwiseMax(b));
  std::optional<double> nearest;
  const Vec3d d = b - a;
  bvh_.overlapping(box, [&](Index t) {
    // Moller-Trumbore segment / triangle intersection.
    const Triangle& tri = surface_.triangles[t];
    const Vec3d p0 = corner(surface_, tri, 0), e1 = corner(surface_, tri, 1) - p0, e2 = corner(surface_, tri, 2) - p0;
    const Vec3d q = d.cross(e2);
    const double det = e1.dot(q);
    if (det == 0) return;
    const Vec3d s = a - p0;
    const double bu = s.dot(q) / det;
    const Vec3d r = s.cross(e1);
    const double bv = d.dot(r) / det;
    const double f = e2.dot(r) / det;
    if (bu < 0 || bv < 0 || bu + bv > 1 || f < 0 || f > 1) return;
    if (!nearest || f < *nearest) nearest = f;
  });
  return nearest;
}

}  // namespace vrd
