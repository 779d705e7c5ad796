#pragma once
// The XPBD multiplier update (eqs. 1-6) shared by every constraint type.

#include "vrdeform/sim/particles.h"

namespace vrd {

/// Compliance and damping of one constraint for one (sub)step of size h.
///
/// Damping is given as a time tau = alpha * beta (s): with the damping beta of eq. 5, XPBD16 eq. 26
/// has gamma = alphaTilde * betaTilde / h = alpha * beta / h = tau / h. tau is the Rayleigh
/// (stiffness-proportional) damping time: the damping force is tau times the rate of change of the
/// elastic force, whatever units the constraint's compliance has.
struct XpbdCoefficients {
  float alphaTilde;  ///< eq. 2: alpha / h^2
  float gamma;       ///< tau / h

  /// `invH` = 1/h, so that loops over many constraints multiply instead of divide.
  static XpbdCoefficients make(float compliance, float dampingTime, float invH) {
    return {compliance * invH * invH, dampingTime * invH};
  }
};

/// Eq. 1 with the Rayleigh damping of eqs. 5-6 in the form of XPBD16 eq. 26:
///
///   dLambda = (-C - alphaTilde*lambda - gamma * gradC.(p - x)) / ((1 + gamma) * gradC M^-1 gradC^T + alphaTilde)
///
/// `gradMinvGrad` = sum_i w_i |grad_i C|^2; `gradDotDisplacement` = sum_i grad_i C . (p_i - x_i), the
/// motion since the start of the (sub)step (only matters when gamma > 0). Returns 0 when nothing can move.
inline float deltaLambda(float C, float lambda, float gradMinvGrad, const XpbdCoefficients& k,
                         float gradDotDisplacement = 0.0f) {
  const float denominator = (1.0f + k.gamma) * gradMinvGrad + k.alphaTilde;
  if (!(denominator > 1e-20f)) return 0.0f;
  return (-C - k.alphaTilde * lambda - k.gamma * gradDotDisplacement) / denominator;
}

/// Result of projecting one scalar constraint on N particles.
template <int N>
struct Correction {
  float dLambda;
  Vec3 dp[N];  ///< eq. 3: w_i grad_i C dLambda
};

/// Eqs. 1 and 3 for a scalar constraint with value C and gradient grad[i] for particle i.
/// `disp` (null when undamped) holds each particle's motion since the start of the substep.
template <int N>
Correction<N> projectScalar(const Point (&p)[N], float C, const Vec3 (&grad)[N], float lambda,
                            const XpbdCoefficients& k, const Vec3* disp) {
  float gradMinvGrad = 0.0f, gradDotDisp = 0.0f;
  for (int a = 0; a < N; ++a) {
    gradMinvGrad += p[a].w * grad[a].squaredNorm();
    if (disp) gradDotDisp += grad[a].dot(disp[a]);
  }
  Correction<N> out;
  out.dLambda = deltaLambda(C, lambda, gradMinvGrad, k, gradDotDisp);
  for (int a = 0; a < N; ++a) out.dp[a] = (p[a].w * out.dLambda) * grad[a];
  return out;
}

}  // namespace vrd
