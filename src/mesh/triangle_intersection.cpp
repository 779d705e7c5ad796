#include "mesh/triangle_intersection.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace vrd {
namespace {

using Vec2d = Eigen::Matrix<double, 2, 1>;

double snap(double distance, double tol) { return std::abs(distance) <= tol ? 0.0 : distance; }

Vec3d unitNormal(const Triangle3d& t) { return (t[1] - t[0]).cross(t[2] - t[0]).normalized(); }

// Signed distances of q's vertices from the plane of p (unit normal n), snapped to zero within tol.
std::array<double, 3> planeDistances(const Vec3d& n, const Vec3d& origin, const Triangle3d& q, double tol) {
  return {snap(n.dot(q[0] - origin), tol), snap(n.dot(q[1] - origin), tol), snap(n.dot(q[2] - origin), tol)};
}

bool allOneSide(const std::array<double, 3>& d) {
  return (d[0] > 0 && d[1] > 0 && d[2] > 0) || (d[0] < 0 && d[1] < 0 && d[2] < 0);
}

// Drops the coordinate along which n is largest, so the projection keeps areas within sqrt(3).
struct Projection {
  int u, v;
  explicit Projection(const Vec3d& n) {
    int drop = 0;
    n.cwiseAbs().maxCoeff(&drop);
    u = (drop + 1) % 3;
    v = (drop + 2) % 3;
  }
  Vec2d operator()(const Vec3d& x) const { return {x[u], x[v]}; }
};

// Within a plane, by plain signs: which side of the line through a and b p is on (positive on the
// left). For float coordinates in an axis plane the sign is exact; elsewhere only touching
// configurations are in doubt, and they can go either way.
double side(const Vec2d& a, const Vec2d& b, const Vec2d& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

// For p on the line through a and b: whether it lies on the closed segment.
bool withinSegment(const Vec2d& a, const Vec2d& b, const Vec2d& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
         p.y() <= std::max(a.y(), b.y());
}

bool segmentsIntersect(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  const double c1 = side(a, b, c), d1 = side(a, b, d);
  const double a1 = side(c, d, a), b1 = side(c, d, b);
  if (((c1 > 0 && d1 < 0) || (c1 < 0 && d1 > 0)) && ((a1 > 0 && b1 < 0) || (a1 < 0 && b1 > 0))) return true;
  return (c1 == 0 && withinSegment(a, b, c)) || (d1 == 0 && withinSegment(a, b, d)) ||
         (a1 == 0 && withinSegment(c, d, a)) || (b1 == 0 && withinSegment(c, d, b));
}

bool insideTriangle(const std::array<Vec2d, 3>& t, const Vec2d& p) {
  const double s0 = side(t[0], t[1], p), s1 = side(t[1], t[2], p), s2 = side(t[2], t[0], p);
  const bool negative = s0 < 0 || s1 < 0 || s2<0, positive = s0> 0 || s1 > 0 || s2 > 0;
  return !(negative && positive);
}

std::array<Vec2d, 3> project(const Projection& to, const Triangle3d& t) { return {to(t[0]), to(t[1]), to(t[2])}; }

bool segmentIntersectsTriangle2d(const Vec2d& a, const Vec2d& b, const std::array<Vec2d, 3>& t) {
  if (insideTriangle(t, a) || insideTriangle(t, b)) return true;
  for (int k = 0; k < 3; ++k)
    if (segmentsIntersect(a, b, t[k], t[(k + 1) % 3])) return true;
  return false;
}

// segmentIntersectsTriangle with t's unit normal n given.
bool segmentMeetsTriangle(const Vec3d& a, const Vec3d& b, const Triangle3d& t, const Vec3d& n, double tol) {
  const double da = snap(n.dot(a - t[0]), tol), db = snap(n.dot(b - t[0]), tol);
  if ((da > 0 && db > 0) || (da < 0 && db < 0)) return false;
  const Projection to(n);
  const std::array<Vec2d, 3> t2 = project(to, t);
  if (da == 0 && db == 0) return segmentIntersectsTriangle2d(to(a), to(b), t2);
  // Where ab crosses the plane; a snapped endpoint stands for it, off the plane by at most tol.
  const Vec3d crossing = da == 0 ? a : db == 0 ? b : Vec3d(a + (b - a) * (da / (da - db)));
  return insideTriangle(t2, to(crossing));
}

}  // namespace

double intersectionTolerance(const Triangle3d& p, const Triangle3d& q) {
  double longest = 0, largest = 0;
  for (const Triangle3d* t : {&p, &q})
    for (int k = 0; k < 3; ++k) {
      longest = std::max(longest, ((*t)[k] - (*t)[(k + 1) % 3]).norm());
      largest = std::max(largest, (*t)[k].cwiseAbs().maxCoeff());
    }
  return 1e-6 * longest + 2 * FLT_EPSILON * largest;
}

bool segmentIntersectsTriangle(const Vec3d& a, const Vec3d& b, const Triangle3d& t, double tol) {
  return segmentMeetsTriangle(a, b, t, unitNormal(t), tol);
}

bool trianglesIntersect(const Triangle3d& p, const Triangle3d& q, double tol) {
  const Vec3d np = unitNormal(p), nq = unitNormal(q);
  if (allOneSide(planeDistances(np, p[0], q, tol)) || allOneSide(planeDistances(nq, q[0], p, tol))) return false;
  // An extreme point of the (convex) intersection cannot be inside both triangles, so it is a point
  // where an edge of one meets the other. Unlike intervals on the planes' common line, this stays
  // sound for nearly parallel planes: a point snapped onto a plane moves by at most tol.
  for (int k = 0; k < 3; ++k)
    if (segmentMeetsTriangle(p[k], p[(k + 1) % 3], q, nq, tol) ||
        segmentMeetsTriangle(q[k], q[(k + 1) % 3], p, np, tol))
      return true;
  return false;
}

bool facesIntersect(const Triangle3d& p, const Triangle& pIds, const Triangle3d& q, const Triangle& qIds, double tol) {
  int shared = 0, pShared[3], qShared[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (pIds[i] == qIds[j]) {
        pShared[shared] = i;
        qShared[shared] = j;
        ++shared;
      }
  if (shared == 0) return trianglesIntersect(p, q, tol);
  if (shared == 3) return true;  // the same face twice
  if (shared == 2) {
    // Two planes through one edge meet only in it, unless they are one plane and both faces
    // lie on the same side of the edge (folded back onto each other).
    const Vec3d& a = p[pShared[0]];
    const Vec3d edge = p[pShared[1]] - a;
    const Vec3d& c = p[3 - pShared[0] - pShared[1]];
    const Vec3d& d = q[3 - qShared[0] - qShared[1]];
    const bool coplanar = snap(unitNormal(p).dot(d - a), tol) == 0;
    return coplanar && edge.cross(c - a).dot(edge.cross(d - a)) > 0;
  }
  // One shared vertex s: the intersection, if it is more than s, is a segment from s whose other
  // end lies on the edge opposite s in p or in q.
  const int i = pShared[0], j = qShared[0];
  return segmentIntersectsTriangle(p[(i + 1) % 3], p[(i + 2) % 3], q, tol) ||
         segmentIntersectsTriangle(q[(j + 1) % 3], q[(j + 2) % 3], p, tol);
}

}  // namespace vrd
