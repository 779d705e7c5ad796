#pragma once
// Particle contacts: against static colliders with Coulomb friction, and against the user's
// fingertip spheres (paper eqs. 36-39, or, beyond the paper, the sphere against a body's surface
// triangles). All are inequality constraints C >= 0 whose accumulated multiplier stays >= 0;
// lambda/h^2 is the normal contact force (N).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "vrdeform/sim/collider.h"
#include "vrdeform/sim/xpbd.h"

namespace vrd {

/// A particle touching (or about to touch) a collider in the current substep.
struct ColliderContact {
  Index particle;
  Index collider;
  float particleRadius;  ///< the particle's body's contact offset (m)
};

struct ContactCorrection {
  float dLambdaNormal;
  Vec3 dLambdaFriction;  ///< tangential multiplier change; lambda_t/h^2 is the friction force (N)
  Vec3 dp;
};

/// Coulomb friction on accumulated multipliers (cf. SS19 eq. 12): the tangential part of `motion`
/// (the contact point's motion in the substep relative to what it touches) is cancelled while the
/// friction multiplier stays inside the static cone |lambda_t| <= mu_s lambda_n; outside it the
/// multiplier is scaled onto the dynamic cone mu_k lambda_n. `inverseMass`: the contact point's
/// (w for a particle, sum b_k^2 w_k for a triangle's point). Returns the multiplier's change; the
/// point moves by inverseMass times it.
inline Vec3 frictionDelta(const Vec3& motion, const Vec3& normal, float inverseMass, const Vec3& lambdaFriction,
                          float lambdaNormal, float staticFriction, float dynamicFriction) {
  if (lambdaNormal <= 0.0f || staticFriction <= 0.0f || !(inverseMass > 0.0f)) return Vec3::Zero();
  const Vec3 tangential = motion - normal.dot(motion) * normal;
  Vec3 friction = lambdaFriction - tangential / inverseMass;  // stick: cancel all tangential motion
  const float magnitude = friction.norm();
  if (magnitude > staticFriction * lambdaNormal) friction *= dynamicFriction * lambdaNormal / magnitude;
  return friction - lambdaFriction;
}

/// Normal: C = d(p) - r >= 0 (d: signed distance, r: the particle's radius), projected with eq. 1
/// and clamped so the accumulated lambda_n stays >= 0. Friction (frictionDelta): against the
/// particle's motion since the start of the substep, p - x0.
inline ContactCorrection solveColliderContact(const Point& p, const Vec3& x0, const SurfacePoint& surface,
                                              float particleRadius, const Collider& collider, float lambdaNormal,
                                              const Vec3& lambdaFriction, const XpbdCoefficients& k) {
  ContactCorrection out{0.0f, Vec3::Zero(), Vec3::Zero()};
  const float C = surface.distance - particleRadius;
  if (p.w == 0.0f || (C >= 0.0f && lambdaNormal <= 0.0f)) return out;
  const float newNormal = std::max(lambdaNormal + deltaLambda(C, lambdaNormal, p.w, k), 0.0f);
  out.dLambdaNormal = newNormal - lambdaNormal;
  out.dp = p.w * out.dLambdaNormal * surface.normal;
  out.dLambdaFriction = frictionDelta(p.pos + out.dp - x0, surface.normal, p.w, lambdaFriction, newNormal,
                                      collider.staticFriction, collider.dynamicFriction);
  out.dp += p.w * out.dLambdaFriction;
  return out;
}

/// What a fingertip's sphere touches.
enum class FingertipContactMode : std::uint8_t {
  Particles,  ///< the bodies' particles (paper eqs. 36-39); passes between the vertices of a coarse mesh
  Triangles,  ///< the bodies' surface triangles (BodyModel::surface), so it also meets faces between vertices
};

/// Coulomb friction between a fingertip and what it touches (beyond the paper, whose contacts are
/// frictionless): skin grips the surface it presses, so a poke on a slope holds the surface under
/// the finger instead of pushing the body aside.
struct FingertipFriction {
  float staticFriction = 0.0f;   ///< mu_s: sticks while |f_t| <= mu_s f_n
  float dynamicFriction = 0.0f;  ///< mu_k: sliding friction force = mu_k f_n
};

/// A fingertip: a kinematic sphere moved by the user (paper section 5.2).
struct Fingertip {
  Vec3 center;          ///< p_finger in the current substep
  Vec3 goal;            ///< where the centre arrives at the end of the step; substeps move it there linearly
  float radius;         ///< r (m)
  float compliance;     ///< alpha of the contact constraints (m/N)
  bool enabled = true;  ///< a disabled fingertip makes no contacts (e.g. while it holds a grasp)
  FingertipContactMode mode = FingertipContactMode::Particles;  ///< particles (the paper) or surface triangles
  FingertipFriction friction;                                   ///< none: the paper's frictionless contacts
  Vec3 substepStart = center;  ///< the centre at the start of the current substep (friction's reference)
};

/// A particle in the contact set N(r) of a fingertip (eq. 36).
struct FingertipContact {
  Index particle;
  Index fingertip;
};

template <typename S>
struct SphereContactEval {
  S C;         ///< eq. 37: |p - c| - r
  Vec3T<S> n;  ///< eq. 39: grad C = (p - c)/|p - c|; zero at the centre
};

template <typename S>
SphereContactEval<S> evalSphereContact(const Vec3T<S>& p, const Vec3T<S>& center, S radius) {
  const Vec3T<S> d = p - center;
  const S length = d.norm();
  if (!(length > S(0))) return {-radius, Vec3T<S>::Zero()};
  return {length - radius, d / length};
}

/// Eqs. 38-39 with the inequality clamp: returns dLambda (>= -lambda); the particle moves by w n dLambda.
inline Correction<Vec3, 1> solveFingertipContact(const Point& p, const Vec3& center, float radius, float lambda,
                                                 const XpbdCoefficients& k) {
  const SphereContactEval<float> e = evalSphereContact(p.pos, center, radius);
  if (e.n.isZero() || (e.C >= 0.0f && lambda <= 0.0f)) return {0.0f, {Vec3::Zero()}};
  const float newLambda = std::max(lambda + deltaLambda(e.C, lambda, p.w, k), 0.0f);
  const float dLambda = newLambda - lambda;
  return {dLambda, {p.w * dLambda * e.n}};
}

/// The fingertip's friction on a particle it pushes with lambdaNormal, after the normal
/// projection (frictionDelta): against the particle's motion since the start of the substep (from
/// x0) relative to the fingertip's. Returns the multiplier's change; the particle moves by w times it.
inline Vec3 fingertipFriction(const Point& p, const Vec3& x0, const Fingertip& f, float lambdaNormal,
                              const Vec3& lambdaFriction) {
  const Vec3 n = evalSphereContact(p.pos, f.center, f.radius).n;
  return frictionDelta(p.pos - x0 - (f.center - f.substepStart), n, p.w, lambdaFriction, lambdaNormal,
                       f.friction.staticFriction, f.friction.dynamicFriction);
}

/// A surface triangle in the contact set of a fingertip in FingertipContactMode::Triangles.
struct FingertipTriangleContact {
  Index i[3];       ///< world particle indices of the triangle's corners
  Index fingertip;  ///< the fingertip
};

/// Barycentric weights {b0, b1, b2} (>= 0, sum 1) of the point of triangle (a, b, c) closest to p:
/// the Voronoi-region walk of Ericson, Real-Time Collision Detection, section 5.1.5 (vertex
/// regions, then edge regions, else the projection onto the face). The triangle must not be
/// degenerate (edge regions divide by an edge's squared length).
template <typename S>
std::array<S, 3> closestPointOnTriangle(const Vec3T<S>& p, const Vec3T<S>& a, const Vec3T<S>& b, const Vec3T<S>& c) {
  const Vec3T<S> ab = b - a, ac = c - a, ap = p - a;
  const S d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= S(0) && d2 <= S(0)) return {S(1), S(0), S(0)};
  const Vec3T<S> bp = p - b;
  const S d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= S(0) && d4 <= d3) return {S(0), S(1), S(0)};
  const S vc = d1 * d4 - d3 * d2;
  if (vc <= S(0) && d1 >= S(0) && d3 <= S(0)) {
    const S v = d1 / (d1 - d3);
    return {S(1) - v, v, S(0)};
  }
  const Vec3T<S> cp = p - c;
  const S d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= S(0) && d5 <= d6) return {S(0), S(0), S(1)};
  const S vb = d5 * d2 - d1 * d6;
  if (vb <= S(0) && d2 >= S(0) && d6 <= S(0)) {
    const S w = d2 / (d2 - d6);
    return {S(1) - w, S(0), w};
  }
  const S va = d3 * d6 - d5 * d4;
  if (va <= S(0) && d4 - d3 >= S(0) && d5 - d6 >= S(0)) {
    const S w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {S(0), S(1) - w, w};
  }
  const S v = vb / (va + vb + vc), w = vc / (va + vb + vc);
  return {S(1) - v - w, v, w};
}

template <typename S>
struct TriangleContactEval {
  S C;                 ///< |c - q| - r, q the triangle's point closest to the centre c
  Vec3T<S> n;          ///< unit (c - q)/|c - q| = grad_c C; grad_{x_k} C = -b[k] n. Zero: no contact
  std::array<S, 3> b;  ///< barycentric weights of q
};

/// The fingertip sphere (centre c, radius r) against triangle (x0, x1, x2). Beyond the paper, it
/// extends eqs. 37-39 by replacing the particle with the triangle's point closest to the centre,
/// q = b0 x0 + b1 x1 + b2 x2, so that a sphere pressing between the vertices of a coarse mesh
/// meets the face:
///
///   C = |c - q| - r >= 0,   n = (c - q)/|c - q|,   grad_{x_k} C = -b_k n,   grad_c C = n.
///
/// Derivation: |c - q| = min over the triangle's points y = sum_k beta_k x_k (beta in the simplex,
/// a set that does not depend on x) of |c - y|. By the envelope theorem (Danskin) the derivative
/// of the minimum is the partial derivative at the minimiser beta = b: d|c - q|/dx_k = -b_k n.
/// The minimiser is unique off the triangle, so C is differentiable there. With |n| = 1,
/// |grad_{x_k} C|^2 = b_k^2, and eq. 38 becomes dLambda = (-C - alphaTilde lambda) /
/// (sum_k b_k^2 w_k + alphaTilde); eq. 39 moves corner k by w_k grad_{x_k} C dLambda.
///
/// When the centre lies on the triangle (|c - q| within sqrt(eps) of the longest edge) c - q has
/// no usable direction; which side the centre came from is not knowable from positions, so n is
/// the triangle's unit normal (x1 - x0) x (x2 - x0)/|...|, outward for BodyModel::surface (for a
/// cloth, the side its winding makes the front). A centre that has crossed the triangle sees n flip
/// and pushes the triangle the other way, as a particle crossing the centre does in eq. 39.
/// A degenerate (zero-area, to 32 eps relative) triangle gives n = 0, b = 0, C = 0: no contact.
template <typename S>
TriangleContactEval<S> evalFingertipTriangleContact(const Vec3T<S>& x0, const Vec3T<S>& x1, const Vec3T<S>& x2,
                                                    const Vec3T<S>& center, S radius) {
  const Vec3T<S> e1 = x1 - x0, e2 = x2 - x0;
  const Vec3T<S> areaNormal = e1.cross(e2);
  const S longestSq = std::max({e1.squaredNorm(), e2.squaredNorm(), (x2 - x1).squaredNorm()});
  const S twiceArea = areaNormal.norm();
  if (!(twiceArea > S(32) * std::numeric_limits<S>::epsilon() * longestSq))
    return {S(0), Vec3T<S>::Zero(), {S(0), S(0), S(0)}};
  const std::array<S, 3> b = closestPointOnTriangle(center, x0, x1, x2);
  const Vec3T<S> d = center - (b[0] * x0 + b[1] * x1 + b[2] * x2);
  const S length = d.norm();
  if (!(length > std::sqrt(std::numeric_limits<S>::epsilon() * longestSq)))
    return {length - radius, areaNormal / twiceArea, b};
  return {length - radius, d / length, b};
}

/// One projection of a sphere-triangle contact: dLambda, the corners' moves, and the gradient it
/// used. The gradient turns with the triangle while the iterations move it, so the impulse a
/// corner received over a substep is the sum of grad dLambda, not the final lambda times the final
/// gradient; the world accumulates it for its force readouts.
struct TriangleContactCorrection {
  float dLambda;
  Vec3 dp[3];    ///< w_k grad_{x_k} C dLambda
  Vec3 grad[3];  ///< grad_{x_k} C = -b_k n at the positions projected
};

/// Eq. 38 with the inequality clamp for the sphere against a triangle (see
/// evalFingertipTriangleContact): dLambda (>= -lambda) and the corners' moves w_k (-b_k n) dLambda.
/// A degenerate triangle, or one whose closest point only kinematic corners carry
/// (sum_k b_k^2 w_k = 0, e.g. an all-kinematic triangle), does nothing.
inline TriangleContactCorrection solveFingertipTriangleContact(const Point& x0, const Point& x1, const Point& x2,
                                                               const Vec3& center, float radius, float lambda,
                                                               const XpbdCoefficients& k) {
  TriangleContactCorrection out{
      0.0f, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}};
  const TriangleContactEval<float> e = evalFingertipTriangleContact(x0.pos, x1.pos, x2.pos, center, radius);
  if (e.n.isZero() || (e.C >= 0.0f && lambda <= 0.0f)) return out;
  const float w[3] = {x0.w, x1.w, x2.w};
  const float gradMinvGrad = e.b[0] * e.b[0] * w[0] + e.b[1] * e.b[1] * w[1] + e.b[2] * e.b[2] * w[2];
  if (!(gradMinvGrad > 0.0f)) return out;
  const float newLambda = std::max(lambda + deltaLambda(e.C, lambda, gradMinvGrad, k), 0.0f);
  out.dLambda = newLambda - lambda;
  for (int c = 0; c < 3; ++c) {
    out.grad[c] = -e.b[c] * e.n;
    out.dp[c] = (w[c] * out.dLambda) * out.grad[c];
  }
  return out;
}

struct TriangleFriction {
  Vec3 dLambda = Vec3::Zero();  ///< the friction multiplier's change; corner k moves by w_k b_k times it
  std::array<float, 3> b{};     ///< barycentric weights of the point under the fingertip
};

/// The fingertip's friction on a triangle it pushes with lambdaNormal, after the normal
/// projection (frictionDelta): against the motion of the triangle's point under the fingertip
/// (its barycentric weights now, applied to the corners x0 at the start of the substep) relative
/// to the fingertip's, with that point's inverse mass sum_k b_k^2 w_k.
inline TriangleFriction fingertipTriangleFriction(const Point& p0, const Point& p1, const Point& p2, const Vec3& x0,
                                                  const Vec3& x1, const Vec3& x2, const Fingertip& f,
                                                  float lambdaNormal, const Vec3& lambdaFriction) {
  TriangleFriction out;
  if (lambdaNormal <= 0.0f || f.friction.staticFriction <= 0.0f) return out;
  const TriangleContactEval<float> e = evalFingertipTriangleContact(p0.pos, p1.pos, p2.pos, f.center, f.radius);
  if (e.n.isZero()) return out;
  out.b = e.b;
  const Vec3 motion = e.b[0] * (p0.pos - x0) + e.b[1] * (p1.pos - x1) + e.b[2] * (p2.pos - x2);
  const float inverseMass = e.b[0] * e.b[0] * p0.w + e.b[1] * e.b[1] * p1.w + e.b[2] * e.b[2] * p2.w;
  out.dLambda = frictionDelta(motion - (f.center - f.substepStart), e.n, inverseMass, lambdaFriction, lambdaNormal,
                              f.friction.staticFriction, f.friction.dynamicFriction);
  return out;
}

}  // namespace vrd
