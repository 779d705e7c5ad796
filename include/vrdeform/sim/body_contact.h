#pragma once
// Contact between bodies and of a body with itself (beyond the paper, whose bodies meet only
// colliders and fingertips): a surface vertex against a surface triangle, as an inequality
// constraint with a multiplier, Coulomb friction and a contact thickness. lambda/h^2 is the
// normal force (N), so a finger that presses one body into another feels the second through the
// first.

#include <array>
#include <cmath>
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

/// A surface vertex touching (or about to touch) a surface triangle in the current substep. The
/// contact is linearised at the substep's start: the normal and the triangle's contact point
/// (barycentric weights b) are fixed while the iterations run, as a contact plane.
struct BodyContact {
  Index particle;           ///< the vertex (world particle index)
  Index corner[3];          ///< the triangle's corners (world particle indices)
  Index triangle;           ///< the triangle's key: its body's first key + its index in the body's surface
  Vec3 offset;              ///< from the corners' body frame to the vertex's (0 within a body)
  Vec3 normal;              ///< unit, from the triangle towards the vertex
  std::array<float, 3> b;   ///< barycentric weights of the triangle's contact point
  float gap;                ///< the distance kept: the two bodies' thicknesses
  float compliance;         ///< the two bodies' compliances in series (m/N)
  float staticFriction;     ///< mu_s of the pair
  float dynamicFriction;    ///< mu_k of the pair
};

/// Where a vertex x meets triangle (a, b, c): the contact normal, the contact point's weights and
/// the distance along the normal.
struct VertexTriangleTouch {
  Vec3 normal;
  std::array<float, 3> b;
  float distance;  ///< normal . (x - q): negative once x is past the triangle
};

/// The contact plane of vertex x and triangle (a, b, c) (all in one frame), from the closest point
/// q of the triangle (closestPointOnTriangle). Where q is inside the face, the normal is the face
/// normal: the outward one for a closed surface (a soft body's boundary, so a vertex found just
/// inside is pushed back out), else the side x is on (a cloth is two-sided). Where q is on an edge
/// or a corner the normal is (x - q)/|x - q|; on a closed surface only if x is on the triangle's
/// outer side, since inside it another triangle is the one it crossed. Nothing for a degenerate
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
  if (closed && face.dot(d) <= 0.0f) return std::nullopt;
  return VertexTriangleTouch{d / length, w, length};
}

/// One projection of a vertex-triangle contact: dLambda and the moves of the vertex and corners.
struct VertexTriangleCorrection {
  float dLambda = 0.0f;
  Vec3 dp = Vec3::Zero();
  std::array<Vec3, 3> dx{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

/// C = n . (p - sum_k b_k x_k) - gap >= 0 with n and b fixed over the substep (the contact plane),
/// so grad_p C = n and grad_{x_k} C = -b_k n exactly. Eq. 1 with the inequality clamp:
/// dLambda = (-C - alphaTilde lambda) / (w_p + sum_k b_k^2 w_k + alphaTilde), lambda stays >= 0;
/// eq. 3 moves the vertex by w_p n dLambda and corner k by -w_k b_k n dLambda. The corners are
/// given in the vertex's frame. Nothing moves where nothing can (all kinematic).
inline VertexTriangleCorrection solveVertexTriangleContact(const Point& p, const std::array<Point, 3>& x,
                                                           const BodyContact& c, float lambda,
                                                           const XpbdCoefficients& k) {
  VertexTriangleCorrection out;
  const Vec3 q = c.b[0] * x[0].pos + c.b[1] * x[1].pos + c.b[2] * x[2].pos;
  const float C = c.normal.dot(p.pos - q) - c.gap;
  if (C >= 0.0f && lambda <= 0.0f) return out;
  const float inverseMass = p.w + c.b[0] * c.b[0] * x[0].w + c.b[1] * c.b[1] * x[1].w + c.b[2] * c.b[2] * x[2].w;
  if (!(inverseMass > 0.0f)) return out;
  out.dLambda = std::max(lambda + deltaLambda(C, lambda, inverseMass, k), 0.0f) - lambda;
  out.dp = (p.w * out.dLambda) * c.normal;
  for (int j = 0; j < 3; ++j) out.dx[std::size_t(j)] = (-x[std::size_t(j)].w * c.b[std::size_t(j)] * out.dLambda) * c.normal;
  return out;
}

/// Friction of a vertex-triangle contact pushing with lambdaNormal (frictionDelta): against the
/// vertex's motion in the substep relative to the triangle's contact point (p - p0 - sum_k b_k
/// (x_k - x0_k)), with the pair's inverse mass w_p + sum_k b_k^2 w_k. Returns the multiplier's
/// change; the vertex moves by w_p times it and corner k by -w_k b_k times it.
inline Vec3 vertexTriangleFriction(const Point& p, const Vec3& p0, const std::array<Point, 3>& x,
                                   const std::array<Vec3, 3>& x0, const BodyContact& c, float lambdaNormal,
                                   const Vec3& lambdaFriction) {
  Vec3 motion = p.pos - p0;
  float inverseMass = p.w;
  for (std::size_t j = 0; j < 3; ++j) {
    motion -= c.b[j] * (x[j].pos - x0[j]);
    inverseMass += c.b[j] * c.b[j] * x[j].w;
  }
  return frictionDelta(motion, c.normal, inverseMass, lambdaFriction, lambdaNormal, c.staticFriction,
                       c.dynamicFriction);
}

}  // namespace vrd
