#pragma once
// Moving data between the solver's arrays of structs and SIMD lanes. A Point is 16 aligned bytes
// (x, y, z, w), so four loads and a 4x4 transpose give four points' coordinates as lanes; wider
// lanes are built from groups of four (concat) and taken apart the same way (split).

#include <cstring>
#include <utility>

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

/// Four floats at f, and back: anywhere (load4, store4), or 16-byte aligned (a Point: loadPoint,
/// storePoint). The types may alias the floats they read, as the x86 intrinsics' do.
using UnalignedLane4 = float __attribute__((vector_size(16), aligned(4), may_alias));
using AlignedLane4 = float __attribute__((vector_size(16), may_alias));
inline Lane4 load4(const float* f) { return *reinterpret_cast<const UnalignedLane4*>(f); }
inline void store4(float* f, Lane4 v) { *reinterpret_cast<UnalignedLane4*>(f) = v; }

/// Lanes I0..I3 of a and b together (0-3: a's lanes, 4-7: b's): _mm_shuffle_ps's job on any CPU.
template <int I0, int I1, int I2, int I3>
Lane4 shuffle4(Lane4 a, Lane4 b) {
  return __builtin_shufflevector(a, b, I0, I1, I2, I3);
}

// A Point's four floats (x, y, z, w). Not Eigen's data(): the lane code calls no inline function
// that other translation units also emit (lane_sweeps.h).
inline const float* floats(const Point* p) { return reinterpret_cast<const float*>(p); }
inline float* floats(Point* p) { return reinterpret_cast<float*>(p); }
inline Lane4 loadPoint(const Point* p) { return *reinterpret_cast<const AlignedLane4*>(p); }
inline void storePoint(Point* p, Lane4 v) { *reinterpret_cast<AlignedLane4*>(p) = v; }

/// Lane 4g + k of the result is lane 4g + P[k] of a for P[k] < 4 and lane 4g + P[k] - 4 of b
/// otherwise: the same pattern in every group g of four lanes (one unpack or shufps per register).
template <int P0, int P1, int P2, int P3, typename T>
T shuffleGroups(T a, T b) {
  return [&]<std::size_t... L>(std::index_sequence<L...>) {
    constexpr int pick[4] = {P0, P1, P2, P3};
    return __builtin_shufflevector(a, b, int(L / 4 * 4 + pick[L % 4] % 4 + (pick[L % 4] < 4 ? 0 : kWidth<T>))...);
  }
  (std::make_index_sequence<kWidth<T>>{});
}

/// _MM_TRANSPOSE4_PS in every group of four lanes at once: afterwards lane 4g + k of r[c] is what
/// lane 4g + c of r[k] was.
template <typename T>
void transposeGroups(T (&r)[4]) {
  const T t0 = shuffleGroups<0, 4, 1, 5>(r[0], r[1]), t1 = shuffleGroups<2, 6, 3, 7>(r[0], r[1]);
  const T t2 = shuffleGroups<0, 4, 1, 5>(r[2], r[3]), t3 = shuffleGroups<2, 6, 3, 7>(r[2], r[3]);
  r[0] = shuffleGroups<0, 1, 4, 5>(t0, t2), r[1] = shuffleGroups<2, 3, 6, 7>(t0, t2);
  r[2] = shuffleGroups<0, 1, 4, 5>(t1, t3), r[3] = shuffleGroups<2, 3, 6, 7>(t1, t3);
}

/// The points idx[l * stride], l in [0, W), as lanes: coordinates x and inverse masses w. (The
/// indices are read in place from an array of constraints: stride is the constraint's size in
/// Indexes.) Register k holds in group g the point of lane 4g + k, and one transpose of all groups
/// at once turns points into coordinates.
template <typename T>
void loadPoints(const Point* pts, const Index* idx, std::size_t stride, V3<T>& x, T& w) {
  T r[4];
  for (std::size_t k = 0; k < 4; ++k) {
    Lane4 part[kGroups<T>];
    for (std::size_t g = 0; g < kGroups<T>; ++g) part[g] = loadPoint(pts + idx[(4 * g + k) * stride]);
    r[k] = concat<T>(part);
  }
  transposeGroups(r);
  x = {r[0], r[1], r[2]};
  w = r[3];
}

/// Writes lanes [0, count) of x and w to their points: loadPoints backwards. A batch's points are
/// distinct and no other batch moves them meanwhile, so the new position x + dp is stored without
/// reading the point again.
template <typename T>
void storePoints(Point* pts, const Index* idx, std::size_t stride, const V3<T>& x, T w, std::size_t count) {
  T r[4] = {x.x, x.y, x.z, w};
  transposeGroups(r);
  for (std::size_t k = 0; k < 4; ++k) {
    Lane4 part[kGroups<T>];
    split(r[k], part);
    for (std::size_t g = 0; g < kGroups<T>; ++g)
      if (4 * g + k < count) storePoint(pts + idx[(4 * g + k) * stride], part[g]);
  }
}

/// kWidth<T> consecutive points from `pts` as lanes (loadPoints), and back (storePoints).
template <typename T>
void loadConsecutivePoints(const Point* pts, V3<T>& x, T& w) {
  Index idx[kWidth<T>];
  for (std::size_t l = 0; l < kWidth<T>; ++l) idx[l] = Index(l);
  loadPoints(pts, idx, 1, x, w);
}
template <typename T>
void storeConsecutivePoints(Point* pts, const V3<T>& x, T w, std::size_t count) {
  Index idx[kWidth<T>];
  for (std::size_t l = 0; l < kWidth<T>; ++l) idx[l] = Index(l);
  storePoints(pts, idx, 1, x, w, count);
}

/// A per-constraint float field and the one after it (`field` + 1) of W consecutive constraints as
/// two lanes: per group of four constraints, four 8-byte loads and two shuffles instead of a load
/// and an insert per lane and field.
template <typename T, typename C>
std::pair<T, T> fieldPairOf(const C* c, float C::*field) {
  if constexpr (kWidth<T> == 1) {
    const float* f = &(c[0].*field);
    return {f[0], f[1]};
  } else {
    using Pairs = double __attribute__((vector_size(16)));  // two 8-byte pairs of floats
    Lane4 first[kGroups<T>], second[kGroups<T>];
    for (std::size_t g = 0; g < kGroups<T>; ++g) {
      const auto pair = [&](std::size_t l) {
        double bytes;
        std::memcpy(&bytes, &(c[4 * g + l].*field), sizeof bytes);
        return bytes;
      };
      const Lane4 low = Lane4(Pairs{pair(0), pair(1)}),
                  high = Lane4(Pairs{pair(2), pair(3)});  // f0 s0 f1 s1, f2 s2 f3 s3
      first[g] = shuffle4<0, 2, 4, 6>(low, high);
      second[g] = shuffle4<1, 3, 5, 7>(low, high);
    }
    return {concat<T>(first), concat<T>(second)};
  }
}

/// W consecutive Vec3s (12 bytes each, x y z x y z ...) as lanes, and back: per group of four,
/// three 16-byte loads and seven shuffles in, nine shuffles and three stores out (never touching
/// memory past the last Vec3).
template <typename T>
V3<T> loadVec3s(const Vec3* v) {
  Lane4 x[kGroups<T>], y[kGroups<T>], z[kGroups<T>];
  for (std::size_t g = 0; g < kGroups<T>; ++g) {
    const float* f = reinterpret_cast<const float*>(v + 4 * g);
    const Lane4 a = load4(f), b = load4(f + 4), c = load4(f + 8);  // x0y0z0x1 y1z1x2y2 z2x3y3z3
    x[g] = shuffle4<0, 3, 4, 6>(a, shuffle4<2, 2, 5, 5>(b, c));
    y[g] = shuffle4<0, 2, 4, 6>(shuffle4<1, 1, 4, 4>(a, b), shuffle4<3, 3, 6, 6>(b, c));
    z[g] = shuffle4<0, 2, 4, 7>(shuffle4<2, 2, 5, 5>(a, b), c);
  }
  return {concat<T>(x), concat<T>(y), concat<T>(z)};
}
template <typename T>
void storeVec3s(Vec3* v, const V3<T>& lanes) {
  Lane4 x[kGroups<T>], y[kGroups<T>], z[kGroups<T>];
  split(lanes.x, x), split(lanes.y, y), split(lanes.z, z);
  for (std::size_t g = 0; g < kGroups<T>; ++g) {
    float* f = reinterpret_cast<float*>(v + 4 * g);
    // Each output takes two pairs, each pair from a shuffle that holds it in lanes 0 and 2.
    const auto pairs = [](Lane4 first, Lane4 second) { return shuffle4<0, 2, 4, 6>(first, second); };
    store4(f, pairs(shuffle4<0, 0, 4, 4>(x[g], y[g]), shuffle4<0, 0, 5, 5>(z[g], x[g])));      // x0 y0 z0 x1
    store4(f + 4, pairs(shuffle4<1, 1, 5, 5>(y[g], z[g]), shuffle4<2, 2, 6, 6>(x[g], y[g])));  // y1 z1 x2 y2
    store4(f + 8, pairs(shuffle4<2, 2, 7, 7>(z[g], x[g]), shuffle4<3, 3, 7, 7>(y[g], z[g])));  // z2 x3 y3 z3
  }
}

/// W consecutive floats as lanes, and back; with `count` < W only the first `count` (the rest of
/// the lanes are zero when loaded and not stored).
template <typename T>
T loadLanes(const float* f, std::size_t count = kWidth<T>) {
  T v{};
  if (count == kWidth<T>)
    std::memcpy(&v, f, sizeof(T));
  else
    std::memcpy(&v, f, count * sizeof(float));
  return v;
}
template <typename T>
void storeLanes(float* f, T v, std::size_t count = kWidth<T>) {
  std::memcpy(f, &v, (count == kWidth<T> ? kWidth<T> : count) * sizeof(float));
}
template <typename T>
void addLanes(float* f, T delta, std::size_t count = kWidth<T>) {
  storeLanes<T>(f, loadLanes<T>(f, count) + delta, count);
}

}  // namespace vrd::sweeps
