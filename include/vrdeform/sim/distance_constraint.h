#pragma once
// Stretch / distance constraint between two particles (paper section 4.1, eqs. 7-15).

#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct DistanceConstraint {
  Index i[2];        ///< the two particles
  float restLength;  ///< l0 (m)
  float compliance;  ///< alpha (m/N)
};

template <typename V>
struct DistanceEval {
  typename V::Scalar C;  ///< eq. 7: |p1 - p2| - l0; 0 when p1 = p2 (no direction to push along)
  V n;                   ///< eq. 8: grad_p1 C = (p1 - p2)/|p1 - p2|; eq. 9: grad_p2 C = -n. Zero when p1 = p2.
};

template <typename V>
DistanceEval<V> evalDistance(const V& p1, const V& p2, typename V::Scalar restLength) {
  using T = typename V::Scalar;
  const V d = p1 - p2;
  const T length = sqrt(d.squaredNorm());
  const auto apart = length > splat<T>(0.0);
  const T inverse = select(apart, splat<T>(1.0) / length, splat<T>(0.0));
  return {select(apart, length - restLength, splat<T>(0.0)), d * inverse};
}

/// Eqs. 10-15 with damping. (Eqs. 11-12 as printed flip the sign of dp1; eq. 3 is the rule.)
template <typename V>
Correction<V, 2> solveDistance(const V (&x)[2], const typename V::Scalar (&w)[2], typename V::Scalar restLength,
                               typename V::Scalar lambda, const XpbdCoefficientsT<typename V::Scalar>& k,
                               const V* disp = nullptr) {
  const DistanceEval<V> e = evalDistance(x[0], x[1], restLength);
  const V grad[2] = {e.n, -e.n};
  return projectScalar(w, e.C, grad, lambda, k, disp);
}

}  // namespace vrd
