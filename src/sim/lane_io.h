#pragma once
// Moving data between the solver's arrays of structs and SIMD lanes. A Point is 16 aligned bytes
// (x, y, z, w), so four loads and a 4x4 transpose give four points' coordinates as lanes; wider
// lanes are built from groups of four (concat) and taken apart the same way (split).

#include <immintrin.h>

#include <cstring>

#include "vrdeform/math/lanes.h"
#include "vrdeform/sim/particles.h"

namespace vrd::sweeps {

template <typename T>
inline constexpr std::size_t kGroups = kWidth<T> / 4;  ///< groups of four lanes in T

/// Joins groups of four lanes into one T (lanes 4g..4g+3 from part g).
template <typename T>
T concat(const Lane4* part) {
  if constexpr (kWidth<T> == 4) {
    return part[0];
  } else if constexpr (kWidth<T> == 8) {
    return __builtin_shufflevector(part[0], part[1], 0, 1, 2, 3, 4, 5, 6, 7);
  } else {
    static_assert(kWidth<T> == 16);
    using Half = float __attribute__((vector_size(32)));
    const Half low = __builtin_shufflevector(part[0], part[1], 0, 1, 2, 3, 4, 5, 6, 7);
    const Half high = __builtin_shufflevector(part[2], part[3], 0, 1, 2, 3, 4, 5, 6, 7);
    return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  }
}

/// The inverse of concat.
template <typename T>
void split(T v, Lane4* part) {
  if constexpr (kWidth<T> == 4) {
    part[0] = v;
  } else if constexpr (kWidth<T> == 8) {
    part[0] = __builtin_shufflevector(v, v, 0, 1, 2, 3);
    part[1] = __builtin_shufflevector(v, v, 4, 5, 6, 7);
  } else {
    static_assert(kWidth<T> == 16);
    part[0] = __builtin_shufflevector(v, v, 0, 1, 2, 3);
    part[1] = __builtin_shufflevector(v, v, 4, 5, 6, 7);
    part[2] = __builtin_shufflevector(v, v, 8, 9, 10, 11);
    part[3] = __builtin_shufflevector(v, v, 12, 13, 14, 15);
  }
}

// A Point's four floats (x, y, z, w). Not Eigen's data(): the lane code calls no inline function
// that other translation units also emit (lane_sweeps.h).
inline const float* floats(const Point* p) { return reinterpret_cast<const float*>(p); }
inline float* floats(Point* p) { return reinterpret_cast<float*>(p); }

/// The points idx[0..W) as lanes: coordinates x and inverse masses w.
template <typename T>
void loadPoints(const Point* pts, const Index* idx, V3<T>& x, T& w) {
  Lane4 px[kGroups<T>], py[kGroups<T>], pz[kGroups<T>], pw[kGroups<T>];
  for (std::size_t g = 0; g < kGroups<T>; ++g) {
    const Index* i = idx + 4 * g;
    __m128 r0 = _mm_load_ps(floats(pts + i[0])), r1 = _mm_load_ps(floats(pts + i[1]));
    __m128 r2 = _mm_load_ps(floats(pts + i[2])), r3 = _mm_load_ps(floats(pts + i[3]));
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    px[g] = r0, py[g] = r1, pz[g] = r2, pw[g] = r3;
  }
  x = {concat<T>(px), concat<T>(py), concat<T>(pz)};
  w = concat<T>(pw);
}

/// Adds lane l of d to point idx[l]; the points must be distinct.
template <typename T>
void addPoints(Point* pts, const Index* idx, const V3<T>& d) {
  Lane4 px[kGroups<T>], py[kGroups<T>], pz[kGroups<T>];
  split(d.x, px), split(d.y, py), split(d.z, pz);
  for (std::size_t g = 0; g < kGroups<T>; ++g) {
    __m128 r0 = px[g], r1 = py[g], r2 = pz[g], r3 = _mm_setzero_ps();  // w += 0
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    const __m128 rows[4] = {r0, r1, r2, r3};
    for (std::size_t l = 0; l < 4; ++l) {
      float* p = floats(pts + idx[4 * g + l]);
      _mm_store_ps(p, _mm_add_ps(_mm_load_ps(p), rows[l]));
    }
  }
}

/// A per-constraint float field of W consecutive constraints as lanes (T = float: one).
template <typename T, typename C>
T fieldOf(const C* c, float C::*field) {
  if constexpr (kWidth<T> == 1) {
    return c[0].*field;
  } else {
    T v;
    for (std::size_t l = 0; l < kWidth<T>; ++l) v[l] = c[l].*field;
    return v;
  }
}

/// W consecutive floats as lanes, and back.
template <typename T>
T loadLanes(const float* f) {
  T v;
  std::memcpy(&v, f, sizeof(T));
  return v;
}
template <typename T>
void addLanes(float* f, T delta) {
  const T v = loadLanes<T>(f) + delta;
  std::memcpy(f, &v, sizeof(T));
}

}  // namespace vrd::sweeps
