#pragma once
// Particle contacts: against static colliders with Coulomb friction, and against the user's
// fingertip spheres (paper eqs. 36-39). Both are inequality constraints C >= 0 whose accumulated
// multiplier stays >= 0; lambda/h^2 is the normal contact force (N).

#include <algorithm>

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

/// Normal: C = d(p) - r >= 0 (d: signed distance, r: the particle's radius), projected with eq. 1
/// and clamped so the accumulated lambda_n stays >= 0. Friction: the tangential motion since the
/// start of the substep, p - x0, is cancelled while the friction multiplier stays inside the
/// static cone |lambda_t| <= mu_s lambda_n; outside it the multiplier is scaled onto the dynamic
/// cone mu_k lambda_n (Coulomb friction on accumulated multipliers, cf. SS19 eq. 12).
inline ContactCorrection solveColliderContact(const Point& p, const Vec3& x0, const SurfacePoint& surface,
                                              float particleRadius, const Collider& collider, float lambdaNormal,
                                              const Vec3& lambdaFriction, const XpbdCoefficients& k) {
  ContactCorrection out{0.0f, Vec3::Zero(), Vec3::Zero()};
  const float C = surface.distance - particleRadius;
  if (p.w == 0.0f || (C >= 0.0f && lambdaNormal <= 0.0f)) return out;
  const float newNormal = std::max(lambdaNormal + deltaLambda(C, lambdaNormal, p.w, k), 0.0f);
  out.dLambdaNormal = newNormal - lambdaNormal;
  out.dp = p.w * out.dLambdaNormal * surface.normal;
  if (newNormal <= 0.0f || collider.staticFriction <= 0.0f) return out;

  const Vec3 motion = p.pos + out.dp - x0;
  const Vec3 tangential = motion - surface.normal.dot(motion) * surface.normal;
  Vec3 friction = lambdaFriction - tangential / p.w;  // stick: cancel all tangential motion
  const float magnitude = friction.norm();
  if (magnitude > collider.staticFriction * newNormal) friction *= collider.dynamicFriction * newNormal / magnitude;
  out.dLambdaFriction = friction - lambdaFriction;
  out.dp += p.w * out.dLambdaFriction;
  return out;
}

/// A fingertip: a kinematic sphere moved by the user (paper section 5.2).
struct Fingertip {
  Vec3 center;          ///< p_finger in the current substep
  Vec3 goal;            ///< where the centre arrives at the end of the step; substeps move it there linearly
  float radius;         ///< r (m)
  float compliance;     ///< alpha of the contact constraints (m/N)
  bool enabled = true;  ///< a disabled fingertip makes no contacts (e.g. while it holds a grasp)
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

}  // namespace vrd
