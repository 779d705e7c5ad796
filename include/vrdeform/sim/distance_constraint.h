#pragma once
// Stretch / distance constraint between two particles (paper section 4.1, eqs. 7-15).

#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct DistanceConstraint {
  Index i[2];        ///< the two particles
  float restLength;  ///< l0 (m)
  float compliance;  ///< alpha (m/N)
};

template <typename S>
struct DistanceEval {
  S C;         ///< eq. 7: |p1 - p2| - l0
  Vec3T<S> n;  ///< eq. 8: grad_p1 C = (p1 - p2)/|p1 - p2|; eq. 9: grad_p2 C = -n. Zero when p1 = p2.
};

template <typename S>
DistanceEval<S> evalDistance(const Vec3T<S>& p1, const Vec3T<S>& p2, S restLength) {
  const Vec3T<S> d = p1 - p2;
  const S length = d.norm();
  if (!(length > S(0))) return {-restLength, Vec3T<S>::Zero()};
  return {length - restLength, d / length};
}

/// Eqs. 10-15 with damping. (Eqs. 11-12 as printed flip the sign of dp1; eq. 3 is the rule.)
/// Coincident particles give no correction: the direction is undefined.
inline Correction<2> solveDistance(const Point (&p)[2], float restLength, float lambda, const XpbdCoefficients& k,
                                   const Vec3* disp = nullptr) {
  const DistanceEval<float> e = evalDistance(p[0].pos, p[1].pos, restLength);
  const Vec3 grad[2] = {e.n, -e.n};
  return projectScalar(p, e.n.isZero() ? 0.0f : e.C, grad, lambda, k, disp);
}

}  // namespace vrd
