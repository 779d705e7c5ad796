#pragma once
// The XPBD multiplier update (eqs. 1-6) shared by every constraint type. Templated on the
// scalar T (float, double or Lane4) and the 3-vector V (Eigen or V3<T>); see math/lanes.h.

#include "vrdeform/math/lanes.h"
#include "vrdeform/sim/particles.h"

namespace vrd {

/// Compliance and damping of one constraint for one (sub)step of size h.
///
/// Damping is given as a time tau = alpha * beta (s): with the damping beta of eq. 5, XPBD16 eq. 26
/// has gamma = alphaTilde * betaTilde / h = alpha * beta / h = tau / h. tau is the Rayleigh
/// (stiffness-proportional) damping time: the damping force is tau times the rate of change of the
/// elastic force, whatever units the constraint's compliance has.
template <typename T>
struct XpbdCoefficientsT {
  T alphaTilde;  ///< eq. 2: alpha / h^2
  T gamma;       ///< tau / h

  /// `invH` = 1/h, so that loops over many constraints multiply instead of divide.
  static XpbdCoefficientsT make(T compliance, T dampingTime, float invH) {
    return {compliance * (invH * invH), dampingTime * invH};
  }
};
using XpbdCoefficients = XpbdCoefficientsT<float>;

/// Eq. 1 with the Rayleigh damping of eqs. 5-6 in the form of XPBD16 eq. 26:
///
///   dLambda = (-C - alphaTilde*lambda - gamma * gradC.(p - x)) / ((1 + gamma) * gradC M^-1 gradC^T + alphaTilde)
///
/// `gradMinvGrad` = sum_i w_i |grad_i C|^2; `gradDotDisplacement` = sum_i grad_i C . (p_i - x_i), the
/// motion since the start of the (sub)step (only matters when gamma > 0). 0 where nothing can move.
template <typename T>
T deltaLambda(T C, T lambda, T gradMinvGrad, const XpbdCoefficientsT<T>& k, T gradDotDisplacement) {
  const T denominator = (1.0f + k.gamma) * gradMinvGrad + k.alphaTilde;
  const T dLambda = (-C - k.alphaTilde * lambda - k.gamma * gradDotDisplacement) / denominator;
  return select(denominator > 1e-20f, dLambda, splat<T>(0.0));
}
inline float deltaLambda(float C, float lambda, float gradMinvGrad, const XpbdCoefficients& k) {
  return deltaLambda(C, lambda, gradMinvGrad, k, 0.0f);
}

/// Result of projecting one scalar constraint on N particles.
template <typename V, int N>
struct Correction {
  typename V::Scalar dLambda;
  V dp[N];  ///< eq. 3: w_i grad_i C dLambda
};

/// Eqs. 1 and 3 for a scalar constraint with value C and gradient grad[i] for particle i with
/// inverse mass w[i]. `disp` (null when undamped) holds each particle's motion in the substep.
template <typename V, int N>
Correction<V, N> projectScalar(const typename V::Scalar (&w)[N], typename V::Scalar C, const V (&grad)[N],
                               typename V::Scalar lambda, const XpbdCoefficientsT<typename V::Scalar>& k,
                               const V* disp) {
  using T = typename V::Scalar;
  T gradMinvGrad = w[0] * grad[0].squaredNorm(), gradDotDisp = splat<T>(0.0);
  for (int a = 1; a < N; ++a) gradMinvGrad += w[a] * grad[a].squaredNorm();
  if (disp)
    for (int a = 0; a < N; ++a) gradDotDisp += grad[a].dot(disp[a]);
  Correction<V, N> out;
  out.dLambda = deltaLambda(C, lambda, gradMinvGrad, k, gradDotDisp);
  for (int a = 0; a < N; ++a) out.dp[a] = (w[a] * out.dLambda) * grad[a];
  return out;
}

}  // namespace vrd
