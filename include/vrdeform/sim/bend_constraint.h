#pragma once
// Dihedral bending constraint between two triangles that share an edge (paper section 4.3, eq. 24).
//
// Particles: p1, p2 on the shared edge; p3 completes triangle A = (p1, p2, p3), p4 completes
// triangle B = (p1, p2, p4). Eq. 24 measures the unsigned angle arccos(n1.n2), which is pi when
// the pair is flat and has a kink there: bending either way lowers it, so its gradient flips sign
// as the cloth passes through flat and the solver chatters. We use the signed bend angle theta
// (0 when flat, positive folding one way, negative the other), which is pi - arccos(n1.n2) on
// one side of flat and smooth through it, so C = theta - theta0 (wrapped to (-pi, pi]) is eq. 24
// up to sign and keeps a gradient of constant direction.
//
// Gradient: the analytic gradient of Müller et al. 2007, appendix A, rewritten in the equivalent
// closed form (Bridson et al. 2003) that has no 0/0 at flat: with e = p2 - p1, nA = e x (p3 - p1),
// nB = (p4 - p1) x e and the edge coordinates s3 = (p3 - p1).e/|e|^2, s4 = (p4 - p1).e/|e|^2,
//   grad_p3 = -|e| nA/|nA|^2,   grad_p4 = -|e| nB/|nB|^2,
//   grad_p1 = -(1 - s3) grad_p3 - (1 - s4) grad_p4,   grad_p2 = -s3 grad_p3 - s4 grad_p4.
// A moving p3 turns triangle A about the edge at rate 1/height. A triangle of (near) zero area
// has no defined normal; the constraint then does nothing.

#include <cmath>
#include <numbers>

#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct BendConstraint {
  Index i[4];        ///< p1, p2: shared edge; p3, p4: opposite vertices of the two triangles
  float restAngle;   ///< theta0: signed bend angle at rest (rad), 0 for a flat rest pair
  float compliance;  ///< alpha (1/(N m))
};

/// V: a 3-vector of scalar S (Vec3, Vec3d) or of lanes (V3<Lane8>: one constraint per lane).
template <typename V>
struct BendEval {
  using S = typename V::Scalar;
  S theta;    ///< signed bend angle in (-pi, pi]
  S C;        ///< theta - theta0 wrapped to (-pi, pi]
  V grad[4];  ///< zero when a triangle is degenerate
};

template <typename V>
BendEval<V> evalBend(const V& p1, const V& p2, const V& p3, const V& p4, typename V::Scalar restAngle) {
  using S = typename V::Scalar;
  const S pi = splat<S>(std::numbers::pi), zero = splat<S>(0.0);
  const V e = p2 - p1;
  const S e2 = e.squaredNorm();
  const V nA = e.cross(p3 - p1), nB = (p4 - p1).cross(e);
  const S nA2 = nA.squaredNorm(), nB2 = nB.squaredNorm();
  const S tiny = splat<S>(1e-12) * e2 * e2;     // height below 1e-6 |e|
  const auto ok = (nA2 > tiny) & (nB2 > tiny);  // per lane: whatever is computed where not ok is dropped
  const S eLength = sqrt(e2);
  BendEval<V> out;
  out.theta = select(ok, S(atan2(S(nA.cross(nB).dot(e) / eLength), S(nA.dot(nB)))), zero);
  out.C = select(ok, S(out.theta - restAngle), zero);
  out.C = select(out.C > pi, S(out.C - 2.0f * pi), out.C);
  out.C = select(out.C <= -pi, S(out.C + 2.0f * pi), out.C);
  const S s3 = select(ok, S((p3 - p1).dot(e) / e2), zero), s4 = select(ok, S((p4 - p1).dot(e) / e2), zero);
  out.grad[2] = select(ok, S(-eLength / nA2), zero) * nA;
  out.grad[3] = select(ok, S(-eLength / nB2), zero) * nB;
  out.grad[0] = -(1.0f - s3) * out.grad[2] - (1.0f - s4) * out.grad[3];
  out.grad[1] = -s3 * out.grad[2] - s4 * out.grad[3];
  return out;
}

/// Eq. 24 projected with eqs. 1 and 3, for one constraint (V = Vec3) or one per lane (V3<Lane8>).
template <typename V>
Correction<V, 4> solveBend(const V (&x)[4], const typename V::Scalar (&w)[4], typename V::Scalar restAngle,
                           typename V::Scalar lambda, const XpbdCoefficientsT<typename V::Scalar>& k,
                           const V* disp = nullptr) {
  const BendEval<V> e = evalBend(x[0], x[1], x[2], x[3], restAngle);
  return projectScalar(w, e.C, e.grad, lambda, k, disp);
}

}  // namespace vrd
