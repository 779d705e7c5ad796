#pragma once
// Contact between bodies and of a body with itself (beyond the paper, whose bodies meet only
// colliders and fingertips): a surface vertex against a surface triangle, and a surface edge
// against a surface edge where vertices alone would let thin parts pass, as inequality
// constraints with a multiplier, Coulomb friction and a contact thickness. lambda/h^2 is the
// normal force (N), so a finger that presses one body into another feels the second through the
// first.

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "vrdeform/sim/contact.h"

namespace vrd {

/// How one body touches other bodies and itself.
struct BodyContactSettings {
  bool bodies = true;  ///< touches other bodies (that touch bodies too, unless the pair is switched off)
  bool self = false;   ///< touches itself: a surface vertex against its own surface's triangles
  /// Skin (m): two bodies keep their surfaces thickness_a + thickness_b apart, a body's own
  /// surfaces 2 thickness. It also bounds how deep a vertex may sit inside a surface and still be
  /// pushed out (deeper, it is taken for the far side of a thin part, not a penetration).
  float thickness = 0.001f;
  float staticFriction = 0.5f;   ///< mu_s; a pair uses the geometric mean of the two bodies'
  float dynamicFriction = 0.4f;  ///< mu_k; likewise
  float compliance = 0.0f;       ///< alpha of the contacts (m/N)
};

/// What the contacts between two bodies (or of one with itself) use: the distance kept (the two
/// thicknesses), the compliance (the two in series) and the frictions (the geometric means).
struct ContactPair {
  float gap, compliance, staticFriction, dynamicFriction;
};
inline ContactPair contactPair(const BodyContactSettings& a, const BodyContactSettings& b) {
  return {a.thickness + b.thickness, a.compliance + b.compliance, std::sqrt(a.staticFriction * b.staticFriction),
          std::sqrt(a.dynamicFriction * b.dynamicFriction)};
}

/// A point of one body's surface touching (or about to touch) a point of another's (or of its own
/// surface elsewhere) in the current substep: a vertex against a triangle, or an edge against an
/// edge. Each point is a weighted sum of its corners, so the contact's separation is
/// d = sum_k c_k x_k with weights c_k summing to 1 over the first body's corners and to -1 over
/// the other's. The contact is linearised at the substep's start: the normal and the weights are
/// fixed while the iterations run, as a contact plane.
struct BodyContact {
  std::array<Index, 4> particle;  ///< world particle indices: the first body's corners, then the other's
  std::array<float, 4> weight;    ///< c_k: a vertex {1, -b0, -b1, -b2}; an edge pair {1-s, s, -(1-t), -t}
  std::uint32_t firstCorners;     ///< how many corners are the first body's: 1 (vertex) or 2 (edge)
  std::uint64_t key;              ///< identifies the pair of features, for the warm start
  Vec3 offset;                    ///< from the other body's frame to the first's (0 within a body)
  Vec3 normal;                    ///< unit, from the other body's point towards the first's
  ContactPair pair;               ///< the gap, compliance and frictions of the two bodies
};

/// Where a vertex x meets triangle (a, b, c): the contact normal, the contact point's weights and
/// the distance along the normal.
struct VertexTriangleTouch {
  Vec3 normal;
  std::array<float, 3> b;
  float distance;  ///< normal . (x - q): negative once x is past the triangle
};

/// On a closed surface, how far above a triangle's plane (as a share of its distance) a vertex
/// beside an edge must be to touch it: one level with the plane, beside a neighbouring face of a
/// flat part of the surface, touches nothing (about 6 degrees).
inline constexpr float kSideOfPlane = 0.1f;

/// The contact plane of vertex x and triangle (a, b, c) (all in one frame), from the closest point
/// q of the triangle (closestPointOnTriangle). Where q is inside the face, the normal is the face
/// normal: the outward one for a closed surface (a soft body's boundary, so a vertex found just
/// inside is pushed back out), else the side x is on (a cloth is two-sided). Where q is on an edge
/// or a corner the normal is (x - q)/|x - q|; on a closed surface only if x is on the triangle's
/// outer side (kSideOfPlane), since inside it another triangle is the one it crossed. Nothing for a degenerate
/// triangle (zero area to 32 eps relative) or x on an edge.
inline std::optional<VertexTriangleTouch> touchVertexTriangle(const Vec3& x, const Vec3& a, const Vec3& b,
                                                              const Vec3& c, bool closed) {
  const Vec3 areaNormal = (b - a).cross(c - a);
  const float longestSq = std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
  const float twiceArea = areaNormal.norm();
  if (!(twiceArea > 32.0f * std::numeric_limits<float>::epsilon() * longestSq)) return std::nullopt;
  const Vec3 face = areaNormal / twiceArea;
  const std::array<float, 3> w = closestPointOnTriangle(x, a, b, c);
  const Vec3 d = x - (w[0] * a + w[1] * b + w[2] * c);
  if (w[0] > 0.0f && w[1] > 0.0f && w[2] > 0.0f) {
    const Vec3 n = closed || face.dot(d) >= 0.0f ? face : Vec3(-face);
    return VertexTriangleTouch{n, w, n.dot(d)};
  }
  const float length = d.norm();
  if (!(length > std::sqrt(std::numeric_limits<float>::epsilon() * longestSq))) return std::nullopt;
  if (closed && !(face.dot(d) > kSideOfPlane * length)) return std::nullopt;
  return VertexTriangleTouch{d / length, w, length};
}

/// Where edge (p0, p1) meets edge (q0, q1) (one frame): the closest points p0 + s (p1 - p0) and
/// q0 + t (q1 - q0) (Ericson, Real-Time Collision Detection, 5.1.9) and the unit normal between them,
/// from the second edge to the first. Only where both are inside their edges (0 < s, t < 1): at an
/// end it is a vertex near an edge or face, which the vertex-triangle contacts hold. Nothing for
/// (nearly) parallel edges or edges that meet.
struct EdgeEdgeTouch {
  Vec3 normal;
  float s, t;
  float distance;
};
inline std::optional<EdgeEdgeTouch> touchEdgeEdge(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const float a = d1.squaredNorm(), e = d2.squaredNorm(), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const float denominator = a * e - b * b;  // |d1 x d2|^2
  if (!(denominator > 1e-6f * a * e)) return std::nullopt;
  const float s = (b * f - c * e) / denominator, t = (b * s + f) / e;
  if (!(s > 0.0f && s < 1.0f && t > 0.0f && t < 1.0f)) return std::nullopt;
  const Vec3 d = p0 + s * d1 - (q0 + t * d2);
  const float length = d.norm();
  if (!(length > std::sqrt(std::numeric_limits<float>::epsilon() * std::max(a, e)))) return std::nullopt;
  return EdgeEdgeTouch{d / length, s, t, length};
}

/// One projection of a body contact: dLambda and each corner's move.
struct BodyContactCorrection {
  float dLambda = 0.0f;
  std::array<Vec3, 4> dx{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

/// C = n . sum_k c_k x_k - gap >= 0 with n and c fixed over the substep (the contact plane), so
/// grad_{x_k} C = c_k n exactly. Eq. 1 with the inequality clamp:
/// dLambda = (-C - alphaTilde lambda) / (sum_k c_k^2 w_k + alphaTilde), lambda stays >= 0; eq. 3
/// moves corner k by w_k c_k n dLambda. The corners are given in the first body's frame. Nothing
/// moves where nothing can (all kinematic). Since the weights sum to 1 and -1 on the two sides,
/// sum_k m_k dx_k = 0: the contact moves no momentum between the pair and the rest of the world.
inline BodyContactCorrection solveBodyContact(const std::array<Point, 4>& x, const BodyContact& c, float lambda,
                                              const XpbdCoefficients& k) {
  BodyContactCorrection out;
  Vec3 d = Vec3::Zero();
  float inverseMass = 0.0f;
  for (std::size_t j = 0; j < 4; ++j) {
    d += c.weight[j] * x[j].pos;
    inverseMass += c.weight[j] * c.weight[j] * x[j].w;
  }
  const float C = c.normal.dot(d) - c.pair.gap;
  if ((C >= 0.0f && lambda <= 0.0f) || !(inverseMass > 0.0f)) return out;
  out.dLambda = std::max(lambda + deltaLambda(C, lambda, inverseMass, k), 0.0f) - lambda;
  for (std::size_t j = 0; j < 4; ++j) out.dx[j] = (x[j].w * c.weight[j] * out.dLambda) * c.normal;
  return out;
}

/// Friction of a body contact pushing with lambdaNormal (frictionDelta): against the contact
/// points' relative motion in the substep, sum_k c_k (x_k - x0_k), with the pair's inverse mass
/// sum_k c_k^2 w_k. Returns the multiplier's change; corner k moves by w_k c_k times it.
inline Vec3 bodyContactFriction(const std::array<Point, 4>& x, const std::array<Vec3, 4>& x0, const BodyContact& c,
                                float lambdaNormal, const Vec3& lambdaFriction) {
  Vec3 motion = Vec3::Zero();
  float inverseMass = 0.0f;
  for (std::size_t j = 0; j < 4; ++j) {
    motion += c.weight[j] * (x[j].pos - x0[j]);
    inverseMass += c.weight[j] * c.weight[j] * x[j].w;
  }
  return frictionDelta(motion, c.normal, inverseMass, lambdaFriction, lambdaNormal, c.pair.staticFriction,
                       c.pair.dynamicFriction);
}

}  // namespace vrd
