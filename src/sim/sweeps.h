#pragma once
// One Gauss-Seidel sweep per constraint type over a body. Distance, volume and strain are written
// once for lane width 1 (float, Eigen vectors) and 4 (Lane4, V3<Lane4>): with T = Lane4 a sweep
// takes four consecutive, independent constraints at a time (lane_batches.h), which is the same
// sweep as taking them one by one. Bending and shape matching run one at a time.

#include <cstring>
#include <type_traits>

#include "vrdeform/sim/body.h"
#include "vrdeform/sim/lane_batches.h"

namespace vrd::sweeps {

template <typename T>
inline constexpr std::size_t kWidth = std::is_same_v<T, Lane4> ? kLanes : 1;
template <typename T>
using VecOf = std::conditional_t<std::is_same_v<T, Lane4>, V3<Lane4>, Vec3>;

/// The N particles of one constraint (T = float) or of kLanes constraints (T = Lane4), with their
/// inverse masses and, when damped, their motion since the start of the substep.
template <typename T, std::size_t N, bool Damped>
struct Gathered {
  using V = VecOf<T>;
  V x[N], disp[N];
  T w[N];
  Index idx[N][kWidth<T>];

  template <typename C>
  Gathered(const C* c, const Point* pred, const Point* start) {
    for (std::size_t a = 0; a < N; ++a) {
      for (std::size_t l = 0; l < kWidth<T>; ++l) idx[a][l] = c[l].i[a];
      load(pred, idx[a], x[a], w[a]);
      if constexpr (Damped) {
        V xs;
        T ws;
        load(start, idx[a], xs, ws);
        disp[a] = x[a] - xs;
      }
    }
  }
  const V* displacement() const { return Damped ? disp : nullptr; }

  void scatter(const V (&dp)[N], Point* pred) const {
    for (std::size_t a = 0; a < N; ++a) add(pred, idx[a], dp[a]);
  }

 private:
  static void load(const Point* pts, const Index (&i)[1], Vec3& x, float& w) {
    x = pts[i[0]].pos;
    w = pts[i[0]].w;
  }
  static void add(Point* pts, const Index (&i)[1], const Vec3& d) { pts[i[0]].pos += d; }

  // A Point is 16 aligned bytes (x, y, z, w): four loads and a transpose give the lanes.
  static void load(const Point* pts, const Index (&i)[kLanes], V3<Lane4>& x, Lane4& w) {
    __m128 r0 = _mm_load_ps(pts[i[0]].pos.data()), r1 = _mm_load_ps(pts[i[1]].pos.data());
    __m128 r2 = _mm_load_ps(pts[i[2]].pos.data()), r3 = _mm_load_ps(pts[i[3]].pos.data());
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    x = {r0, r1, r2};
    w = r3;
  }
  static void add(Point* pts, const Index (&i)[kLanes], const V3<Lane4>& d) {
    __m128 r0 = d.x, r1 = d.y, r2 = d.z, r3 = _mm_setzero_ps();  // w += 0
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    const __m128 rows[kLanes] = {r0, r1, r2, r3};
    for (std::size_t l = 0; l < kLanes; ++l) {
      float* p = pts[i[l]].pos.data();
      _mm_store_ps(p, _mm_add_ps(_mm_load_ps(p), rows[l]));
    }
  }
};

/// A per-constraint float field as a scalar or as lanes.
template <typename T, typename C>
T fieldOf(const C* c, float C::*field) {
  if constexpr (std::is_same_v<T, Lane4>)
    return Lane4{c[0].*field, c[1].*field, c[2].*field, c[3].*field};
  else
    return c[0].*field;
}

template <typename T>
T loadLambda(const float* lambda) {
  T v;
  std::memcpy(&v, lambda, sizeof(T));
  return v;
}
template <typename T>
void addLambda(float* lambda, T delta) {
  const T v = loadLambda<T>(lambda) + delta;
  std::memcpy(lambda, &v, sizeof(T));
}

// Everything a sweep needs about the body it runs over.
struct Range {
  Point* pred;         // the body's predicted positions
  const Point* start;  // and its positions at the start of the substep
  float invH;          // 1/h
};

template <typename T, bool Damped>
void distance(const DistanceConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau,
              const Range& r) {
  for (std::size_t i = begin; i < end; i += kWidth<T>) {
    const Gathered<T, 2, Damped> g(c + i, r.pred, r.start);
    const auto k =
        XpbdCoefficientsT<T>::make(fieldOf<T>(c + i, &DistanceConstraint::compliance), splat<T>(tau), r.invH);
    const auto out = solveDistance(g.x, g.w, fieldOf<T>(c + i, &DistanceConstraint::restLength),
                                   loadLambda<T>(lambda + i), k, g.displacement());
    addLambda(lambda + i, out.dLambda);
    g.scatter(out.dp, r.pred);
  }
}

template <typename T, bool Damped>
void volume(const VolumeConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, const Range& r) {
  for (std::size_t i = begin; i < end; i += kWidth<T>) {
    const Gathered<T, 4, Damped> g(c + i, r.pred, r.start);
    const auto k = XpbdCoefficientsT<T>::make(fieldOf<T>(c + i, &VolumeConstraint::compliance), splat<T>(tau), r.invH);
    const auto out = solveVolume(g.x, g.w, fieldOf<T>(c + i, &VolumeConstraint::restVolume), loadLambda<T>(lambda + i),
                                 k, g.displacement());
    addLambda(lambda + i, out.dLambda);
    g.scatter(out.dp, r.pred);
  }
}

// Strain weights a_k (strainWeights) of one tet or of kLanes tets. For lanes: column i of each
// tet's D_rest^-1 is contiguous (Eigen is column-major) and holds (a_1[i], a_2[i], a_3[i]), so one
// load per tet and a transpose give a_1[i], a_2[i] and a_3[i] for all four. The fourth float read
// belongs to the next column or to the constraint's compliance and is discarded.
template <typename T>
void strainWeightsOf(const StrainConstraint* c, VecOf<T> (&a)[4]) {
  if constexpr (std::is_same_v<T, Lane4>) {
    Lane4 column[3][3];  // column[i][k] = a_{k+1}[i]
    for (int i = 0; i < 3; ++i) {
      __m128 r0 = _mm_loadu_ps(c[0].invRestShape.data() + 3 * i), r1 = _mm_loadu_ps(c[1].invRestShape.data() + 3 * i);
      __m128 r2 = _mm_loadu_ps(c[2].invRestShape.data() + 3 * i), r3 = _mm_loadu_ps(c[3].invRestShape.data() + 3 * i);
      _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
      column[i][0] = r0, column[i][1] = r1, column[i][2] = r2;
    }
    for (int k = 0; k < 3; ++k) a[k + 1] = {column[0][k], column[1][k], column[2][k]};
    a[0] = -(a[1] + a[2] + a[3]);
  } else {
    const auto w = strainWeights(c[0].invRestShape);
    for (int k = 0; k < 4; ++k) a[k] = w[k];
  }
}

// The six strain multipliers of one tet, or of kLanes consecutive tets as lanes: the tets' 24
// floats are contiguous, so components 0-3 and 2-5 of each tet load as one vector each and two
// transposes give all six lanes.
template <typename T>
StrainLambdaT<T> loadStrainLambda(const StrainLambda* lambda) {
  if constexpr (std::is_same_v<T, Lane4>) {
    static_assert(sizeof(StrainLambda) == 6 * sizeof(float));
    const float* f = lambda->data();
    __m128 a0 = _mm_loadu_ps(f), a1 = _mm_loadu_ps(f + 6), a2 = _mm_loadu_ps(f + 12), a3 = _mm_loadu_ps(f + 18);
    __m128 b0 = _mm_loadu_ps(f + 2), b1 = _mm_loadu_ps(f + 8), b2 = _mm_loadu_ps(f + 14), b3 = _mm_loadu_ps(f + 20);
    _MM_TRANSPOSE4_PS(a0, a1, a2, a3);
    _MM_TRANSPOSE4_PS(b0, b1, b2, b3);
    return {a0, a1, a2, a3, b2, b3};
  } else {
    return *lambda;
  }
}

template <typename T>
void addStrainLambda(StrainLambda* lambda, const StrainLambdaT<T>& delta) {
  if constexpr (std::is_same_v<T, Lane4>) {
    const StrainLambdaT<Lane4> sum = [&] {
      StrainLambdaT<Lane4> s = loadStrainLambda<Lane4>(lambda);
      for (int c = 0; c < kStrainComponents; ++c) s[c] += delta[c];
      return s;
    }();
    __m128 a0 = sum[0], a1 = sum[1], a2 = sum[2], a3 = sum[3], b0 = sum[4], b1 = sum[5], b2 = _mm_setzero_ps(),
           b3 = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(a0, a1, a2, a3);  // a_l = components 0-3 of tet l
    _MM_TRANSPOSE4_PS(b0, b1, b2, b3);  // b_l = components 4, 5 of tet l (and two zeros)
    const __m128 low[kLanes] = {a0, a1, a2, a3}, high[kLanes] = {b0, b1, b2, b3};
    for (std::size_t l = 0; l < kLanes; ++l) {
      float* f = lambda[l].data();
      _mm_storeu_ps(f, low[l]);
      _mm_storel_pi(reinterpret_cast<__m64*>(f + 4), high[l]);
    }
  } else {
    for (int c = 0; c < kStrainComponents; ++c) (*lambda)[c] += delta[c];
  }
}

template <typename T, bool Damped>
void strain(const StrainConstraint* c, std::size_t begin, std::size_t end, StrainLambda* lambda,
            const ConstraintDamping& damping, const Range& r) {
  for (std::size_t i = begin; i < end; i += kWidth<T>) {
    const Gathered<T, 4, Damped> g(c + i, r.pred, r.start);
    VecOf<T> a[4];
    strainWeightsOf<T>(c + i, a);
    const auto stretch = XpbdCoefficientsT<T>::make(fieldOf<T>(c + i, &StrainConstraint::stretchCompliance),
                                                    splat<T>(damping.strainStretch), r.invH);
    const auto shear = XpbdCoefficientsT<T>::make(fieldOf<T>(c + i, &StrainConstraint::shearCompliance),
                                                  splat<T>(damping.strainShear), r.invH);
    const auto out = solveStrain(g.x, g.w, a, loadStrainLambda<T>(lambda + i), stretch, shear, g.displacement());
    addStrainLambda<T>(lambda + i, out.dLambda);
    g.scatter(out.dp, r.pred);
  }
}

// Bending, one at a time (not batched: bending is the lighter part of a cloth).
template <bool Damped>
void bend(const std::vector<BendConstraint>& constraints, float* lambda, float tau, const Range& r) {
  for (std::size_t c = 0; c < constraints.size(); ++c) {
    const BendConstraint& con = constraints[c];
    const Gathered<float, 4, Damped> g(&con, r.pred, r.start);
    const auto out = solveBend(g.x, g.w, con.restAngle, lambda[c], XpbdCoefficients::make(con.compliance, tau, r.invH),
                               g.displacement());
    lambda[c] += out.dLambda;
    g.scatter(out.dp, r.pred);
  }
}

// Shape matching: the frame (eqs. 25-27) once, then every particle's goal (eq. 28).
inline void shapeMatching(const ShapeMatchModel& sm, Vec3* lambda, Eigen::Quaterniond& rotation, float tau,
                          const Range& r) {
  Point* pred = r.pred;
  const Point* start = r.start;
  const ShapeMatchFrame frame = shapeMatchFrame(pred, sm, rotation);
  const XpbdCoefficients k = XpbdCoefficients::make(sm.compliance, tau, r.invH);
  for (std::size_t i = 0; i < sm.restOffsets.size(); ++i) {
    const Vec3 goal = frame.centroid + frame.rotation * sm.restOffsets[i];
    const Vec3 disp = tau > 0.0f ? Vec3(pred[i].pos - start[i].pos) : Vec3::Zero();
    const Vec3 dLambda = solveShapeMatchParticle(pred[i], goal, lambda[i], k, disp);
    lambda[i] += dLambda;
    pred[i].pos += pred[i].w * dLambda;
  }
}

/// Calls run(damped, width, begin, end) for the lanes over the batched prefix (when simd is on) and
/// then one at a time over the rest; damped and width are compile-time tags.
template <typename Run>
void widths(bool simd, std::size_t batched, std::size_t count, bool damped, Run run) {
  const std::size_t split = simd ? batched : 0;
  if (damped) {
    run(std::integral_constant<bool, true>{}, Lane4{}, 0, split);
    run(std::integral_constant<bool, true>{}, 0.0f, split, count);
  } else {
    run(std::integral_constant<bool, false>{}, Lane4{}, 0, split);
    run(std::integral_constant<bool, false>{}, 0.0f, split, count);
  }
}

}  // namespace vrd::sweeps
