#pragma once
// Tetrahedral Green-strain constraints (paper section 4.5, eqs. 29-34; Strain Based Dynamics).
//
// F = D_def D_rest^-1 (eq. 31) and S = F^T F. Six scalar constraints per tet: three stretch
// C = S_ii - 1 (eq. 33, rest stretch s_i = 1) and three shear C = S_ij, i < j (eq. 34), each with
// its own multiplier, solved one after another inside the tet (local Gauss-Seidel).

#include <array>

#include "vrdeform/sim/particles.h"
#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct StrainConstraint {
  Index i[4];               ///< particles of the tet, positively oriented at rest
  Mat3 invRestShape;        ///< D_rest^-1 (eq. 29): inverse of the rest edge vectors p2-p1, p3-p1, p4-p1
  float stretchCompliance;  ///< alpha of the three stretch constraints
  float shearCompliance;    ///< alpha of the three shear constraints
};

/// Components in solve order: stretch 00, 11, 22, then shear 01, 02, 12.
inline constexpr int kStrainComponents = 6;
inline constexpr int kStrainAxes[kStrainComponents][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
inline bool isStretchComponent(int c) { return c < 3; }

/// The six multipliers of a tet's strain constraints, in component order.
using StrainLambda = std::array<float, kStrainComponents>;

/// Per-particle weights a_k with F = sum_k p_k a_k^T: a_k is row k-1 of D_rest^-1 and
/// a_0 = -(a_1 + a_2 + a_3). So grad_{p_k} S_ij = a_k[i] f_j + a_k[j] f_i for the columns f of F.
template <typename S>
std::array<Vec3T<S>, 4> strainWeights(const Mat3T<S>& invRestShape) {
  std::array<Vec3T<S>, 4> a;
  for (int k = 0; k < 3; ++k) a[k + 1] = invRestShape.row(k).transpose();
  a[0] = -(a[1] + a[2] + a[3]);
  return a;
}

/// Eqs. 30-31: deformation gradient of the tet.
template <typename S>
Mat3T<S> deformationGradient(const Vec3T<S>& p1, const Vec3T<S>& p2, const Vec3T<S>& p3, const Vec3T<S>& p4,
                             const Mat3T<S>& invRestShape) {
  Mat3T<S> deformed;
  deformed << p2 - p1, p3 - p1, p4 - p1;
  return deformed * invRestShape;
}

template <typename S>
struct StrainComponentEval {
  S C;
  Vec3T<S> grad[4];
};

/// Eqs. 33-34: one strain component's constraint value and its gradient for each particle.
template <typename S>
StrainComponentEval<S> evalStrainComponent(const Vec3T<S>& p1, const Vec3T<S>& p2, const Vec3T<S>& p3,
                                           const Vec3T<S>& p4, const Mat3T<S>& invRestShape, int component) {
  const Mat3T<S> F = deformationGradient(p1, p2, p3, p4, invRestShape);
  const auto a = strainWeights(invRestShape);
  const int i = kStrainAxes[component][0], j = kStrainAxes[component][1];
  StrainComponentEval<S> e;
  e.C = F.col(i).dot(F.col(j)) - (i == j ? S(1) : S(0));
  for (int k = 0; k < 4; ++k) e.grad[k] = a[k][i] * F.col(j) + a[k][j] * F.col(i);
  return e;
}

struct StrainCorrection {
  StrainLambda dLambda;
  Vec3 dp[4];
};

/// One local Gauss-Seidel sweep over the six strain constraints of a tet.
///
/// Equal, up to rounding, to projecting the components one after another and re-evaluating F from
/// the moved particles each time (solveStrainReference), but in closed form: with
/// B = sum_k w_k a_k a_k^T, the correction of component (i, j) changes F by a rank-1 term and the
/// denominator of eq. 1 is sum_k w_k |grad_k S_ij|^2 = B_ii |f_j|^2 + B_jj |f_i|^2 + 2 B_ij S_ij.
/// The particles' corrections are gathered in U and applied once: dp_k = w_k U a_k.
/// (Columns are kept as separate 3-vectors: Eigen's partly vectorised 3x3 ops stall on
/// store-to-load forwarding here.)
inline StrainCorrection solveStrain(const Point (&p)[4], const Mat3& invRestShape, const StrainLambda& lambda,
                                    const XpbdCoefficients& stretch, const XpbdCoefficients& shear,
                                    const Vec3* disp = nullptr) {
  const auto a = strainWeights(invRestShape);
  Vec3 f[3], D[3], U[3];  // columns of F, of the displacement gradient (damping) and of U
  float B[3][3];
  for (int i = 0; i < 3; ++i) {
    f[i] = a[0][i] * p[0].pos + a[1][i] * p[1].pos + a[2][i] * p[2].pos + a[3][i] * p[3].pos;
    D[i] = disp ? Vec3(a[0][i] * disp[0] + a[1][i] * disp[1] + a[2][i] * disp[2] + a[3][i] * disp[3]) : Vec3::Zero();
    U[i].setZero();
    for (int j = i; j < 3; ++j)
      B[i][j] = B[j][i] = p[0].w * a[0][i] * a[0][j] + p[1].w * a[1][i] * a[1][j] + p[2].w * a[2][i] * a[2][j] +
                          p[3].w * a[3][i] * a[3][j];
  }

  StrainCorrection out;
  for (int c = 0; c < kStrainComponents; ++c) {
    const int i = kStrainAxes[c][0], j = kStrainAxes[c][1];
    const float Sij = f[i].dot(f[j]);
    Vec3 gi, gj;  // changes of U's columns i and j
    if (i == j) {
      out.dLambda[c] = deltaLambda(Sij - 1.0f, lambda[c], 4.0f * B[i][i] * Sij, stretch, 2.0f * f[i].dot(D[i]));
      gi = 2.0f * out.dLambda[c] * f[i];
      gj.setZero();
    } else {
      const float gradMinvGrad = B[i][i] * f[j].squaredNorm() + B[j][j] * f[i].squaredNorm() + 2.0f * B[i][j] * Sij;
      out.dLambda[c] = deltaLambda(Sij, lambda[c], gradMinvGrad, shear, f[j].dot(D[i]) + f[i].dot(D[j]));
      gi = out.dLambda[c] * f[j];
      gj = out.dLambda[c] * f[i];
    }
    U[i] += gi;
    U[j] += gj;
    for (int m = 0; m < 3; ++m) {  // F += gi B_i. + gj B_j. (the rank-1 change of F)
      const Vec3 dF = B[i][m] * gi + B[j][m] * gj;
      f[m] += dF;
      if (disp) D[m] += dF;
    }
  }
  for (int k = 0; k < 4; ++k) out.dp[k] = p[k].w * (a[k][0] * U[0] + a[k][1] * U[1] + a[k][2] * U[2]);
  return out;
}

/// The straightforward form of solveStrain: project each component with eq. 1 and eq. 3,
/// re-evaluating F from the moved particles every time. The reference for tests and the baseline
/// in benchmarks.
inline StrainCorrection solveStrainReference(const Point (&p)[4], const Mat3& invRestShape,
                                             const StrainLambda& lambda,
                                             const XpbdCoefficients& stretch, const XpbdCoefficients& shear,
                                             const Vec3* disp = nullptr) {
  Vec3 x[4], d[4];
  for (int k = 0; k < 4; ++k) {
    x[k] = p[k].pos;
    d[k] = disp ? disp[k] : Vec3::Zero();
  }
  StrainCorrection out;
  for (int c = 0; c < kStrainComponents; ++c) {
    const StrainComponentEval<float> e = evalStrainComponent(x[0], x[1], x[2], x[3], invRestShape, c);
    float gradMinvGrad = 0.0f, gradDotDisp = 0.0f;
    for (int k = 0; k < 4; ++k) {
      gradMinvGrad += p[k].w * e.grad[k].squaredNorm();
      if (disp) gradDotDisp += e.grad[k].dot(d[k]);
    }
    out.dLambda[c] = deltaLambda(e.C, lambda[c], gradMinvGrad, isStretchComponent(c) ? stretch : shear, gradDotDisp);
    for (int k = 0; k < 4; ++k) {
      const Vec3 step = p[k].w * out.dLambda[c] * e.grad[k];
      x[k] += step;
      d[k] += step;
    }
  }
  for (int k = 0; k < 4; ++k) out.dp[k] = x[k] - p[k].pos;
  return out;
}

}  // namespace vrd
