#pragma once
// Signed tetrahedral volume constraint (paper section 4.2, eqs. 16-23).
//
// C = V - V0 with the signed volume V, so an inverted tet (V < 0) has C < -V0 and is pushed back
// through zero to positive volume; a constraint on |V| would leave it inverted.

#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct VolumeConstraint {
  Index i[4];        ///< particles of the tet, positively oriented at rest
  float restVolume;  ///< V0 (m^3)
  float compliance;  ///< alpha (m^3/N)
};

template <typename V>
struct VolumeEval {
  typename V::Scalar C;  ///< eq. 17: V - V0
  V grad[4];             ///< eqs. 18-21: one sixth of each opposite face's area vector, pointing outward
};

template <typename V>
VolumeEval<V> evalVolume(const V& p1, const V& p2, const V& p3, const V& p4, typename V::Scalar restVolume) {
  const auto sixth = splat<typename V::Scalar>(1.0 / 6.0);
  VolumeEval<V> e;
  e.grad[3] = sixth * V((p2 - p1).cross(p3 - p1));
  e.C = e.grad[3].dot(p4 - p1) - restVolume;  // eq. 16: V = (p2-p1)x(p3-p1).(p4-p1)/6
  e.grad[0] = sixth * V((p2 - p3).cross(p4 - p3));
  e.grad[1] = sixth * V((p3 - p1).cross(p4 - p1));
  e.grad[2] = sixth * V((p1 - p2).cross(p4 - p2));
  return e;
}

/// Eqs. 22-23 with damping: one XPBD projection of the volume constraint.
template <typename V>
Correction<V, 4> solveVolume(const V (&x)[4], const typename V::Scalar (&w)[4], typename V::Scalar restVolume,
                             typename V::Scalar lambda, const XpbdCoefficientsT<typename V::Scalar>& k,
                             const V* disp = nullptr) {
  const VolumeEval<V> e = evalVolume(x[0], x[1], x[2], x[3], restVolume);
  return projectScalar(w, e.C, e.grad, lambda, k, disp);
}

}  // namespace vrd
