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

template <typename S>
struct VolumeEval {
  S C;               ///< eq. 17: V - V0
  Vec3T<S> grad[4];  ///< eqs. 18-21: one sixth of each opposite face's area vector, pointing outward
};

template <typename S>
VolumeEval<S> evalVolume(const Vec3T<S>& p1, const Vec3T<S>& p2, const Vec3T<S>& p3, const Vec3T<S>& p4,
                         S restVolume) {
  constexpr S sixth = S(1) / S(6);
  VolumeEval<S> e;
  e.C = signedTetVolume(p1, p2, p3, p4) - restVolume;
  e.grad[0] = sixth * (p2 - p3).cross(p4 - p3);
  e.grad[1] = sixth * (p3 - p1).cross(p4 - p1);
  e.grad[2] = sixth * (p1 - p2).cross(p4 - p2);
  e.grad[3] = sixth * (p2 - p1).cross(p3 - p1);
  return e;
}

/// Eqs. 22-23 with damping: one XPBD projection of the volume constraint.
inline Correction<4> solveVolume(const Point (&p)[4], float restVolume, float lambda, const XpbdCoefficients& k,
                                 const Vec3* disp = nullptr) {
  const VolumeEval<float> e = evalVolume(p[0].pos, p[1].pos, p[2].pos, p[3].pos, restVolume);
  return projectScalar(p, e.C, e.grad, lambda, k, disp);
}

}  // namespace vrd
