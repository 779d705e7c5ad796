#pragma once
// Small fixed-size maths types. Eigen's fixed-size types are fully inlined; the templated
// aliases let the constraint maths run in double for derivative checks and float in the solver.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

namespace vrd {

template <typename S>
using Vec3T = Eigen::Matrix<S, 3, 1>;
template <typename S>
using Mat3T = Eigen::Matrix<S, 3, 3>;

using Vec3 = Vec3T<float>;
using Vec3d = Vec3T<double>;  ///< mesh processing, reference maths
using Mat3 = Mat3T<float>;
using Quat = Eigen::Quaternionf;

/// Particle and element indices.
using Index = std::uint32_t;

/// Clamps to [0, 1] with NaN read as 0: how every normalised haptic value leaves the engine.
inline float clampUnit(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }  // NaN fails v > 0

inline bool isFinite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace vrd
