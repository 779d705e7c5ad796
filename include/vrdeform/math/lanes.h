#pragma once
// One maths, every width: a 3-vector over a scalar type T that is float (the scalar solver),
// double (derivative checks) or a lane type: Lane4 (4 lanes: SSE on x86-64, NEON on aarch64),
// Lane8 (AVX2) or Lane16 (AVX-512), that many constraints at once. Constraint kernels written over
// V3<T> run unchanged at every width, so the scalar and SIMD paths cannot drift apart. The member
// names follow Eigen's so that the same kernels also accept Eigen vectors. The lanes are the
// compiler's generic vectors (GCC and Clang), so this header holds no instruction set's
// intrinsics; Lane8 and Lane16 exist only in translation units compiled for their instruction
// set (src/sim/x86/sweeps_avx*.cpp), chosen at run time.

#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>

namespace vrd {

/// Four floats processed together (GCC/Clang vector extension; SSE or NEON registers).
using Lane4 = float __attribute__((vector_size(16)));
#ifdef __AVX2__
using Lane8 = float __attribute__((vector_size(32)));  ///< eight floats (AVX2)
#endif
#ifdef __AVX512F__
using Lane16 = float __attribute__((vector_size(64)));  ///< sixteen floats (AVX-512)
#endif

/// Lanes of T: 1 for float, 4 for Lane4, ...
template <typename T>
inline constexpr std::size_t kWidth = sizeof(T) / sizeof(float);

/// v in every lane of T.
template <typename T>
T splat(double v) {
  if constexpr (std::is_floating_point_v<T>)
    return T(v);
  else
    return T{} + float(v);
}

/// Per-lane choice: `mask ? a : b` (mask is a bool for scalars and a lane mask for lanes).
template <typename M, typename T>
T select(M mask, T a, T b) {
  return mask ? a : b;
}

/// f applied to each lane of v (the compiler turns a lane-wise sqrt into one vector instruction).
template <typename T, typename F>
T lanewise(T v, F f) {
  return [&]<std::size_t... L>(std::index_sequence<L...>) { return T{f(v[L])...}; }
  (std::make_index_sequence<kWidth<T>>{});
}

inline float sqrt(float v) { return std::sqrt(v); }
inline double sqrt(double v) { return std::sqrt(v); }
inline Lane4 sqrt(Lane4 v) {
  return lanewise(v, [](float x) { return std::sqrt(x); });
}
#ifdef __AVX2__
inline Lane8 sqrt(Lane8 v) {
  return lanewise(v, [](float x) { return std::sqrt(x); });
}
#endif
#ifdef __AVX512F__
inline Lane16 sqrt(Lane16 v) {
  return lanewise(v, [](float x) { return std::sqrt(x); });
}
#endif

/// atan2 per lane to within 1 ulp (SLEEF on x86-64, in each width's translation unit:
/// src/sim/sweeps_sse.cpp, src/sim/x86/sweeps_avx*.cpp; the C library's lane by lane elsewhere).
inline float atan2(float y, float x) { return std::atan2(y, x); }
inline double atan2(double y, double x) { return std::atan2(y, x); }
Lane4 atan2(Lane4 y, Lane4 x);
#ifdef __AVX2__
Lane8 atan2(Lane8 y, Lane8 x);
#endif
#ifdef __AVX512F__
Lane16 atan2(Lane16 y, Lane16 x);
#endif

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
