#pragma once
// Rotation part of a 3x3 matrix, robust to degenerate and inverted input.
//
// Müller, Bender, Chentanez, Macklin, "A Robust Method to Extract the Rotational Part of
// Deformations" (MIG 2016): R = rot(q) maximises tr(R^T A) over rotations. Each step rotates q by
// the angular velocity omega = sum_i r_i x a_i / (|sum_i r_i . a_i| + eps), where r_i and a_i are the
// columns of R and A. It returns a proper rotation for any A, including det(A) <= 0 and rank < 3,
// and converges in a few steps when q is warm-started from the previous call.

#include "vrdeform/math/types.h"

namespace vrd {

/// Updates q in place to the rotation closest to A; returns the number of steps taken.
template <typename S>
int extractRotation(const Mat3T<S>& A, Eigen::Quaternion<S>& q, int maxSteps = 20) {
  const S tolerance = std::is_same_v<S, float> ? S(1e-6) : S(1e-12);
  int step = 0;
  for (; step < maxSteps; ++step) {
    const Mat3T<S> R = q.toRotationMatrix();
    const Vec3T<S> torque = R.col(0).cross(A.col(0)) + R.col(1).cross(A.col(1)) + R.col(2).cross(A.col(2));
    const S alignment = std::abs(R.col(0).dot(A.col(0)) + R.col(1).dot(A.col(1)) + R.col(2).dot(A.col(2)));
    const Vec3T<S> omega = torque / (alignment + S(1e-9));
    const S angle = omega.norm();
    if (!(angle > tolerance)) break;  // also stops on NaN
    q = Eigen::Quaternion<S>(Eigen::AngleAxis<S>(angle, omega / angle)) * q;
    q.normalize();
  }
  return step;
}

}  // namespace vrd
