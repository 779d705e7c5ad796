#pragma once
// One maths, three widths: a 3-vector over a scalar type T that is float (the scalar solver),
// double (derivative checks) or Lane4, four floats in an SSE register (four constraints at once).
// Constraint kernels written over V3<T> run unchanged at every width, so the scalar and SIMD
// paths cannot drift apart. The member names follow Eigen's so that the same kernels also accept
// Eigen vectors.

#include <xmmintrin.h>
#include <cmath>

namespace vrd {

/// Four floats processed together (GCC/Clang vector extension; SSE on any x86-64).
using Lane4 = float __attribute__((vector_size(16)));

template <typename T>
T splat(double v) {
  return T(v);
}
template <>
inline Lane4 splat<Lane4>(double v) {
  const float f = float(v);
  return Lane4{f, f, f, f};
}

/// Per-lane choice: `mask ? a : b` (mask is a bool for scalars and a lane mask for Lane4).
template <typename M, typename T>
T select(M mask, T a, T b) {
  return mask ? a : b;
}

inline float sqrt(float v) { return std::sqrt(v); }
inline double sqrt(double v) { return std::sqrt(v); }
inline Lane4 sqrt(Lane4 v) { return _mm_sqrt_ps(v); }

template <typename T>
struct V3 {
  using Scalar = T;
  T x, y, z;

  static V3 Zero() { return {splat<T>(0.0f), splat<T>(0.0f), splat<T>(0.0f)}; }
  T dot(const V3& o) const { return x * o.x + y * o.y + z * o.z; }
  V3 cross(const V3& o) const { return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x}; }
  T squaredNorm() const { return dot(*this); }
  T operator[](int i) const { return i == 0 ? x : i == 1 ? y : z; }

  V3 operator+(const V3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  V3 operator-(const V3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  V3 operator-() const { return {-x, -y, -z}; }
  V3 operator*(T s) const { return {x * s, y * s, z * s}; }
  V3 operator/(T s) const { return {x / s, y / s, z / s}; }
  V3& operator+=(const V3& o) { return *this = *this + o; }
  friend V3 operator*(T s, const V3& v) { return v * s; }
};

}  // namespace vrd
