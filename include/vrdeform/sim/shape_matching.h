#pragma once
// Global shape matching of a whole body (paper section 4.4, eqs. 25-28).
//
// Goal positions g_i = c2 + R (x_i - c1) (eq. 27), where c1 and c2 are the mass-weighted centroids
// of the rest and current shapes and R is the rotation minimising eq. 25. That minimiser is the
// rotation of A_pq = sum_i m_i (p_i - c2)(x_i - c1)^T (Müller et al. 2005); eq. 26's extra factor
// A_qq^-1 is symmetric and only matters for linear (non-rigid) matching, so we leave it out.
// R comes from the robust extraction of math/rotation.h, which also handles inverted and flat
// shapes. Each particle then gets the vector constraint C_i = p_i - g_i (eq. 28), projected with
// eqs. 1 and 3 with the goal held fixed.
//
// Compliance is per unit mass, alpha_i = alpha / m_i: the energy (m_i / 2 alpha) |p_i - g_i|^2 pulls
// every particle back at the same rate whatever its mass, and the corrections then conserve linear
// and angular momentum (sum_i m_i (g_i - p_i) = 0 and sum_i m_i (p_i - c2) x (g_i - p_i) = 0 at the
// optimal R). With the paper's unit masses it is the plain compliance.

#include <vector>

#include "vrdeform/math/rotation.h"
#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct ShapeMatchModel {
  Vec3 restCentroid;              ///< c1 (eq. 25's t0)
  std::vector<Vec3> restOffsets;  ///< x_i - c1, one per particle of the body
  std::vector<float> mass;        ///< m_i, the weights of eq. 25
  float totalMass;
  float compliance;  ///< alpha (m/N for a 1 kg particle; see above)
};

struct ShapeMatchFrame {
  Vec3 centroid;  ///< c2
  Mat3 rotation;  ///< R
};

/// Eq. 25's sums over some of the particles: sum_i m_i p_i and A_pq. In double: a rotation that
/// stops short by float's 1e-6 rad lags a spinning body, and the goals would then brake the spin
/// every projection.
struct ShapeMatchSums {
  Vec3T<double> weighted = Vec3T<double>::Zero();
  Mat3T<double> Apq = Mat3T<double>::Zero();

  ShapeMatchSums& operator+=(const ShapeMatchSums& o) {
    weighted += o.weighted;
    Apq += o.Apq;
    return *this;
  }
};

/// The sums over particles [begin, end) with rest offsets q (ShapeMatchModel::restOffsets) and masses.
inline ShapeMatchSums shapeMatchSums(const Point* p, const Vec3* q, const float* mass, std::size_t begin,
                                     std::size_t end) {
  ShapeMatchSums s;
  for (std::size_t i = begin; i < end; ++i) {
    const Vec3T<double> mp = double(mass[i]) * p[i].pos.cast<double>();
    s.weighted += mp;
    // sum_i m_i (p_i - c2) q_i^T = sum_i m_i p_i q_i^T because sum_i m_i q_i = 0.
    s.Apq.noalias() += mp * q[i].cast<double>().transpose();
  }
  return s;
}

/// Eqs. 25-27: centroid and best-fit rotation from the sums over every particle. `rotation`
/// warm-starts the extraction and receives the result.
inline ShapeMatchFrame shapeMatchFrame(const ShapeMatchSums& all, const ShapeMatchModel& model,
                                       Eigen::Quaterniond& rotation) {
  extractRotation(all.Apq, rotation);
  return {(all.weighted / double(model.totalMass)).cast<float>(), rotation.toRotationMatrix().cast<float>()};
}
inline ShapeMatchFrame shapeMatchFrame(const Point* p, const ShapeMatchModel& model, Eigen::Quaterniond& rotation) {
  return shapeMatchFrame(shapeMatchSums(p, model.restOffsets.data(), model.mass.data(), 0, model.restOffsets.size()),
                         model, rotation);
}

/// Eq. 28 for one particle: the change of its vector multiplier; its correction is w dLambda.
/// `k` holds alpha/h^2 of a unit-mass particle and tau/h; `change` (damping) is the change of
/// C = p - goal in the substep: the particle's motion less its goal's, so that the frame's own
/// motion (a body falling or turning) is not damped.
inline Vec3 solveShapeMatchParticle(const Point& p, const Vec3& goal, const Vec3& lambda, const XpbdCoefficients& k,
                                    const Vec3& change = Vec3::Zero()) {
  if (p.w == 0.0f) return Vec3::Zero();
  const float alphaTilde = k.alphaTilde * p.w;                                // alpha_i = alpha / m_i
  const float invDenominator = 1.0f / ((1.0f + k.gamma) * p.w + alphaTilde);  // one division, not three
  return (goal - p.pos - alphaTilde * lambda - k.gamma * change) * invDenominator;
}

}  // namespace vrd
