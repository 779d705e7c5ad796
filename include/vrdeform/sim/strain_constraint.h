#pragma once
// Tetrahedral Green-strain constraints (paper section 4.5, eqs. 29-34; Strain Based Dynamics).
//
// F = D_def D_rest^-1 (eq. 31) and S = F^T F. Six scalar constraints per tet: three stretch
// C = S_ii - 1 (eq. 33, rest stretch s_i = 1) and three shear C = S_ij, i < j (eq. 34), each with
// its own multiplier, solved one after another inside the tet (local Gauss-Seidel).

#include <algorithm>
#include <array>
#include <span>
#include <utility>
#include <vector>

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
template <typename T>
using StrainLambdaT = std::array<T, kStrainComponents>;
using StrainLambda = StrainLambdaT<float>;

/// The strain multipliers of a body, component by component: component c of tet j at
/// data()[c * size() + j], so that SIMD lanes load and store one component of consecutive tets
/// as one vector (instead of transposing six-float records).
class StrainLambdas {
 public:
  void assign(std::size_t tets) { count_ = tets, values_.assign(kStrainComponents * tets, 0.0f); }
  std::size_t size() const { return count_; }
  StrainLambda operator[](std::size_t j) const {
    StrainLambda l;
    for (int c = 0; c < kStrainComponents; ++c) l[c] = values_[std::size_t(c) * count_ + j];
    return l;
  }
  float* data() { return values_.data(); }
  std::span<const float> values() const { return values_; }
  std::size_t bytes() const { return values_.capacity() * sizeof(float); }

 private:
  std::vector<float> values_;
  std::size_t count_ = 0;
};

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

template <typename V>
struct StrainCorrection {
  StrainLambdaT<typename V::Scalar> dLambda;
  V dp[4];
};

/// Eq. 31 through the strain weights: F's columns f_i = sum_k a_k[i] x_k.
template <typename V>
void deformationColumns(const V (&x)[4], const V (&a)[4], V (&f)[3]) {
  for (int i = 0; i < 3; ++i) f[i] = a[0][i] * x[0] + a[1][i] * x[1] + a[2][i] * x[2] + a[3][i] * x[3];
}

/// The closed-form local solve of one tet's strain constraints (see solveStrain), kept as state so
/// that further constraints on the same tet can follow it in the same pass (strain_volume.h):
/// F's columns f (kept current as corrections are made), F at the start of the substep (damping),
/// B = sum_k w_k a_k a_k^T, and U, which gathers the corrections: dp_k = w_k U a_k.
template <typename V>
struct TetLocalSolve {
  using T = typename V::Scalar;
  V f[3], fStart[3], U[3];
  T B[3][3];
  bool damped;

  /// `fStart`: F's columns at the start of the substep (damping); null when undamped.
  TetLocalSolve(const V (&x)[4], const T (&w)[4], const V (&a)[4], const V* fStart) : damped(fStart != nullptr) {
    deformationColumns(x, a, f);
    for (int i = 0; i < 3; ++i) {
      this->fStart[i] = fStart ? fStart[i] : V(V::Zero());
      U[i] = V::Zero();
      for (int j = i; j < 3; ++j)
        B[i][j] = B[j][i] =
            w[0] * a[0][i] * a[0][j] + w[1] * a[1][i] * a[1][j] + w[2] * a[2][i] * a[2][j] + w[3] * a[3][i] * a[3][j];
    }
  }

  /// Eqs. 33-34: projects the six strain components one after another; returns their dLambda.
  StrainLambdaT<T> strain(const StrainLambdaT<T>& lambda, const XpbdCoefficientsT<T>& stretch,
                          const XpbdCoefficientsT<T>& shear) {
    StrainLambdaT<T> dLambda;
    [&]<int... c>(std::integer_sequence<int, c...>) { ((dLambda[c] = component<c>(lambda[c], stretch, shear)), ...); }
    (std::make_integer_sequence<int, kStrainComponents>{});
    return dLambda;
  }

  /// The particles' corrections so far: dp_k = w_k U a_k.
  void corrections(const T (&w)[4], const V (&a)[4], V (&dp)[4]) const {
    for (int k = 0; k < 4; ++k) dp[k] = w[k] * V(a[k][0] * U[0] + a[k][1] * U[1] + a[k][2] * U[2]);
  }

 private:
  // One component; c is a template argument so that i and j are constants and f, B and U stay in
  // registers (a runtime loop over kStrainAxes keeps them in memory).
  template <int c>
  T component(T lambda, const XpbdCoefficientsT<T>& stretch, const XpbdCoefficientsT<T>& shear) {
    constexpr int i = kStrainAxes[c][0], j = kStrainAxes[c][1];
    const T Sij = f[i].dot(f[j]);
    if constexpr (i == j) {
      // grad C . disp = f_j.D_i + f_i.D_j with the displacement gradient D = F - F(start).
      const T gradDotDisp = damped ? T(2.0f * f[i].dot(f[i] - fStart[i])) : splat<T>(0.0);
      const T dLambda = deltaLambda(T(Sij - 1.0f), lambda, T(4.0f * B[i][i] * Sij), stretch, gradDotDisp);
      const V gi = (2.0f * dLambda) * f[i];  // the change of U's column i
      U[i] += gi;
      for (int m = 0; m < 3; ++m) f[m] += B[i][m] * gi;  // F += gi B_i. (the rank-1 change of F)
      return dLambda;
    } else {
      const T gradMinvGrad = B[i][i] * f[j].squaredNorm() + B[j][j] * f[i].squaredNorm() + 2.0f * B[i][j] * Sij;
      const T gradDotDisp = damped ? T(f[j].dot(f[i] - fStart[i]) + f[i].dot(f[j] - fStart[j])) : splat<T>(0.0);
      const T dLambda = deltaLambda(Sij, lambda, gradMinvGrad, shear, gradDotDisp);
      const V gi = dLambda * f[j], gj = dLambda * f[i];  // the changes of U's columns i and j
      U[i] += gi;
      U[j] += gj;
      for (int m = 0; m < 3; ++m) f[m] += B[i][m] * gi + B[j][m] * gj;  // F += gi B_i. + gj B_j.
      return dLambda;
    }
  }
};

/// solveStrain given F's columns at the start of the substep (deformationColumns of the positions
/// then; null when undamped) instead of the particles' motion since.
template <typename V>
StrainCorrection<V> solveStrainFromStart(const V (&x)[4], const typename V::Scalar (&w)[4], const V (&a)[4],
                                         const StrainLambdaT<typename V::Scalar>& lambda,
                                         const XpbdCoefficientsT<typename V::Scalar>& stretch,
                                         const XpbdCoefficientsT<typename V::Scalar>& shear, const V* fStart) {
  TetLocalSolve<V> s(x, w, a, fStart);
  StrainCorrection<V> out;
  out.dLambda = s.strain(lambda, stretch, shear);
  s.corrections(w, a, out.dp);
  return out;
}

/// One local Gauss-Seidel sweep over the six strain constraints of a tet, for particles x with
/// inverse masses w and strain weights a (see strainWeights).
///
/// Equal, up to rounding, to projecting the components one after another and re-evaluating F from
/// the moved particles each time (solveStrainReference), but in closed form: with
/// B = sum_k w_k a_k a_k^T, the correction of component (i, j) changes F by a rank-1 term and the
/// denominator of eq. 1 is sum_k w_k |grad_k S_ij|^2 = B_ii |f_j|^2 + B_jj |f_i|^2 + 2 B_ij S_ij.
/// The particles' corrections are gathered in U and applied once: dp_k = w_k U a_k.
template <typename V>
StrainCorrection<V> solveStrain(const V (&x)[4], const typename V::Scalar (&w)[4], const V (&a)[4],
                                const StrainLambdaT<typename V::Scalar>& lambda,
                                const XpbdCoefficientsT<typename V::Scalar>& stretch,
                                const XpbdCoefficientsT<typename V::Scalar>& shear, const V* disp = nullptr) {
  V fStart[3];
  if (disp) {
    V start[4];
    for (int k = 0; k < 4; ++k) start[k] = x[k] - disp[k];
    deformationColumns(start, a, fStart);
  }
  return solveStrainFromStart(x, w, a, lambda, stretch, shear, disp ? fStart : nullptr);
}

/// The straightforward form of solveStrain: project each component with eq. 1 and eq. 3,
/// re-evaluating F from the moved particles every time. The reference for tests and the baseline
/// in benchmarks.
inline StrainCorrection<Vec3> solveStrainReference(const Vec3 (&x0)[4], const float (&w)[4], const Mat3& invRestShape,
                                                   const StrainLambda& lambda, const XpbdCoefficients& stretch,
                                                   const XpbdCoefficients& shear, const Vec3* disp = nullptr) {
  Vec3 x[4], d[4];
  for (int k = 0; k < 4; ++k) {
    x[k] = x0[k];
    d[k] = disp ? disp[k] : Vec3::Zero();
  }
  StrainCorrection<Vec3> out;
  for (int c = 0; c < kStrainComponents; ++c) {
    const StrainComponentEval<float> e = evalStrainComponent(x[0], x[1], x[2], x[3], invRestShape, c);
    const Correction<Vec3, 4> r =
        projectScalar(w, e.C, e.grad, lambda[c], isStretchComponent(c) ? stretch : shear, disp ? d : nullptr);
    out.dLambda[c] = r.dLambda;
    for (int k = 0; k < 4; ++k) {
      x[k] += r.dp[k];
      d[k] += r.dp[k];
    }
  }
  for (int k = 0; k < 4; ++k) out.dp[k] = x[k] - x0[k];
  return out;
}

}  // namespace vrd
