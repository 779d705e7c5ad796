#pragma once
// A tet's strain and volume constraints in one pass: the six strain components (eqs. 33-34), then
// the volume constraint (eqs. 16-23), projected one after another on the same tet as the
// separate sweeps would, but the volume step works on the deformation gradient that the strain
// solve keeps current (TetLocalSolve), so the tet's particles are read and written once.
//
// With F = D D_rest^-1 (eq. 31) the signed volume is V = V_D det F, V_D = 1 / (6 det D_rest^-1) the
// volume D_rest^-1 was made from. det F changes with column f_i by the cofactor column
// c_i = f_{i+1} x f_{i+2}, so grad_k V = V_D sum_i a_k[i] c_i: the same form as the strain
// corrections, dp_k = w_k U a_k with U += dLambda V_D c.

#include "vrdeform/sim/strain_constraint.h"
#include "vrdeform/sim/volume_constraint.h"

namespace vrd {

template <typename V>
struct StrainVolumeCorrection {
  StrainLambdaT<typename V::Scalar> dLambdaStrain;
  typename V::Scalar dLambdaVolume;
  V dp[4];
};

/// Eqs. 16-23 on the tet of `s` after its strain: one XPBD projection of C = V - restVolume with
/// strain weights a; returns dLambda. Leaves f as it was (nothing follows it in the pass).
template <typename V>
typename V::Scalar projectVolume(TetLocalSolve<V>& s, const V (&a)[4], typename V::Scalar restVolume,
                                 typename V::Scalar lambda, const XpbdCoefficientsT<typename V::Scalar>& k) {
  using T = typename V::Scalar;
  const T restShapeVolume = splat<T>(1.0 / 6.0) / a[1].dot(a[2].cross(a[3]));  // V_D (a_1..a_3: rows of D_rest^-1)
  const V c[3] = {s.f[1].cross(s.f[2]), s.f[2].cross(s.f[0]), s.f[0].cross(s.f[1])};
  const T C = restShapeVolume * s.f[0].dot(c[0]) - restVolume;
  // sum_k w_k |grad_k V|^2 = V_D^2 sum_ij B_ij c_i.c_j
  const T cBc = s.B[0][0] * c[0].squaredNorm() + s.B[1][1] * c[1].squaredNorm() + s.B[2][2] * c[2].squaredNorm() +
                2.0f * (s.B[0][1] * c[0].dot(c[1]) + s.B[0][2] * c[0].dot(c[2]) + s.B[1][2] * c[1].dot(c[2]));
  // sum_k grad_k V . disp_k = V_D sum_i c_i . (f_i - f_i(start))
  const T gradDotDisp =
      s.damped ? T(restShapeVolume *
                   (c[0].dot(s.f[0] - s.fStart[0]) + c[1].dot(s.f[1] - s.fStart[1]) + c[2].dot(s.f[2] - s.fStart[2])))
               : splat<T>(0.0);
  const T dLambda = deltaLambda(C, lambda, T(restShapeVolume * restShapeVolume * cBc), k, gradDotDisp);
  const T scale = dLambda * restShapeVolume;
  for (int i = 0; i < 3; ++i) s.U[i] += scale * c[i];
  return dLambda;
}

/// solveStrain, then solveVolume on the moved particles, in one: equal to the two one after the
/// other up to rounding. `fStart`: F's columns at the start of the substep (deformationColumns of
/// the positions then), for damping; null when undamped.
template <typename V>
StrainVolumeCorrection<V> solveStrainVolume(const V (&x)[4], const typename V::Scalar (&w)[4], const V (&a)[4],
                                            const StrainLambdaT<typename V::Scalar>& strainLambda,
                                            const XpbdCoefficientsT<typename V::Scalar>& stretch,
                                            const XpbdCoefficientsT<typename V::Scalar>& shear,
                                            typename V::Scalar restVolume, typename V::Scalar volumeLambda,
                                            const XpbdCoefficientsT<typename V::Scalar>& volume,
                                            const V* fStart = nullptr) {
  TetLocalSolve<V> s(x, w, a, fStart);
  StrainVolumeCorrection<V> out;
  out.dLambdaStrain = s.strain(strainLambda, stretch, shear);
  out.dLambdaVolume = projectVolume(s, a, restVolume, volumeLambda, volume);
  s.corrections(w, a, out.dp);
  return out;
}

}  // namespace vrd
