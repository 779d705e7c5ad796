#pragma once
// One Gauss-Seidel sweep per constraint type over a range of a body's constraints. Distance,
// volume, strain and bending are written once for every width: T = float (one constraint, Eigen
// vectors) or a lane type (lanes.h: kWidth<T> consecutive constraints of one colour at once, which
// is the same sweep as taking them one by one). Shape matching's per-particle sums and goals run
// over consecutive particles at every width.

#include <array>
#include <cstddef>
#include <type_traits>

#include "lane_io.h"
#include "vrdeform/sim/body.h"
#include "vrdeform/sim/strain_volume.h"

namespace vrd::sweeps {

template <typename T>
using VecOf = std::conditional_t<std::is_same_v<T, float>, Vec3, V3<T>>;

/// The N particles of one constraint (T = float) or of kWidth<T> consecutive constraints (lanes),
/// with their inverse masses and, when damped, their positions at the start of the substep. Lanes
/// from `count` on are padding (see forBatches) and are never written back.
template <typename T, std::size_t N, bool Damped>
struct Gathered {
  using V = VecOf<T>;
  V x[N], xStart[N], disp[N];
  T w[N];
  const Index* idx;    // particle a of lane l: idx[l * stride + a]
  std::size_t stride;  // a constraint's size in Indexes
  std::size_t count;

  template <typename C>
  Gathered(const C* c, std::size_t count, const Point* pred, const Point* start)
      : idx(c->i), stride(sizeof(C) / sizeof(Index)), count(count) {
    static_assert(offsetof(C, i) == 0 && sizeof(C) % sizeof(Index) == 0);
    for (std::size_t a = 0; a < N; ++a) {
      load(pred, idx + a, x[a], w[a]);
      if constexpr (Damped) {
        T ws;
        load(start, idx + a, xStart[a], ws);
        disp[a] = x[a] - xStart[a];
      }
    }
  }
  /// Each particle's motion since the start of the substep (null when undamped).
  const V* displacement() const { return Damped ? disp : nullptr; }

  /// Applies a constraint's corrections here, for the next constraint on the same particles.
  void move(const V (&dp)[N]) {
    for (std::size_t a = 0; a < N; ++a) {
      x[a] += dp[a];
      if constexpr (Damped) disp[a] = x[a] - xStart[a];
    }
  }
  /// Writes the positions back.
  void store(Point* pred) const {
    for (std::size_t a = 0; a < N; ++a) {
      if constexpr (kWidth<T> == 1)
        pred[idx[a]].pos = x[a];
      else
        storePoints(pred, idx + a, stride, x[a], w[a], count);
    }
  }

 private:
  void load(const Point* pts, const Index* i, V& x, T& w) const {
    if constexpr (kWidth<T> == 1) {
      x = pts[*i].pos;
      w = pts[*i].w;
    } else {
      loadPoints(pts, i, stride, x, w);
    }
  }
};

// Everything a sweep needs about the body it runs over.
struct Range {
  Point* pred;                    // the body's predicted positions
  const Point* start;             // and its positions at the start of the substep
  float invH;                     // 1/h
  const float* startDeformation;  // Body::startDeformation (damped strain sweeps)
};

// Column i's coordinate d of tet j's F is at deformation[(3 i + d) * tets + j] (Body::startDeformation).
template <typename T>
void loadDeformation(const float* deformation, std::size_t tets, std::size_t first, std::size_t count,
                     VecOf<T> (&f)[3]) {
  for (std::size_t i = 0; i < 3; ++i) {
    const float* column = deformation + 3 * i * tets + first;
    const T x = loadLanes<T>(column, count), y = loadLanes<T>(column + tets, count),
            z = loadLanes<T>(column + 2 * tets, count);
    if constexpr (kWidth<T> == 1)
      f[i] = Vec3(x, y, z);
    else
      f[i] = {x, y, z};
  }
}

/// Calls batch(i, count, c...) for constraints [begin, end) of one or more arrays of the same order,
/// kWidth<T> at a time from c = constraints + i (count = kWidth<T>); the last (end - begin) %
/// kWidth<T> go on copies padded with the first one (count = how many are real), whose padding's
/// results the batch drops (multipliers by loadLanes/addLanes with `count`, positions by
/// Gathered::store).
template <typename T, typename Batch, typename... C>
void forBatches(std::size_t begin, std::size_t end, Batch batch, const C*... constraints) {
  constexpr std::size_t W = kWidth<T>;
  std::size_t i = begin;
  for (; i + W <= end; i += W) batch(i, W, (constraints + i)...);
  if (i == end) return;
  const auto padded = [&]<typename K>(const K* c) {
    std::array<K, W> p;
    for (std::size_t l = 0; l < W; ++l) p[l] = c[l < end - i ? i + l : i];
    return p;
  };
  [&](const auto&... p) { batch(i, end - i, p.data()...); }(padded(constraints)...);
}

// A constraint type with one multiplier per constraint over N particles (distance, volume):
// `solve` is its projection (solveDistance, solveVolume), `rest` its rest value's field.
template <typename T, bool Damped, std::size_t N, typename C, typename Solve>
void oneMultiplier(const C* constraints, std::size_t begin, std::size_t end, float* lambdas, float tau, const Range& r,
                   float C::*rest, Solve solve) {
  const auto batch = [&](std::size_t first, std::size_t count, const C* c) {
    Gathered<T, N, Damped> g(c, count, r.pred, r.start);
    const auto [restValue, compliance] = fieldPairOf<T>(c, rest);  // the compliance follows the rest value
    const auto k = XpbdCoefficientsT<T>::make(compliance, splat<T>(tau), r.invH);
    const auto out = solve(g.x, g.w, restValue, loadLanes<T>(lambdas + first, count), k, g.displacement());
    addLanes<T>(lambdas + first, out.dLambda, count);
    g.move(out.dp);
    g.store(r.pred);
  };
  forBatches<T>(begin, end, batch, constraints);
}

static_assert(offsetof(DistanceConstraint, compliance) == offsetof(DistanceConstraint, restLength) + sizeof(float));
static_assert(offsetof(VolumeConstraint, compliance) == offsetof(VolumeConstraint, restVolume) + sizeof(float));
static_assert(offsetof(BendConstraint, compliance) == offsetof(BendConstraint, restAngle) + sizeof(float));
static_assert(offsetof(StrainConstraint, shearCompliance) ==
              offsetof(StrainConstraint, stretchCompliance) + sizeof(float));

// Each sweep below is one function with its kernels inlined, which saves the calls' cost, but not
// under the sanitizers: instrumenting the flattened sweeps takes minutes to compile, and the
// result is the same either way.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VRD_SWEEP
#else
#define VRD_SWEEP [[gnu::flatten]]
#endif

template <typename T, bool Damped>
VRD_SWEEP void distance(const DistanceConstraint* constraints, std::size_t begin, std::size_t end, float* lambdas,
                        float tau, const Range& r) {
  oneMultiplier<T, Damped, 2>(constraints, begin, end, lambdas, tau, r, &DistanceConstraint::restLength,
                              [](const auto&... a) { return solveDistance(a...); });
}

template <typename T, bool Damped>
VRD_SWEEP void volume(const VolumeConstraint* constraints, std::size_t begin, std::size_t end, float* lambdas,
                      float tau, const Range& r) {
  oneMultiplier<T, Damped, 4>(constraints, begin, end, lambdas, tau, r, &VolumeConstraint::restVolume,
                              [](const auto&... a) { return solveVolume(a...); });
}

// Strain weights a_k (strainWeights) of one tet or of kWidth<T> tets. For lanes, per group of
// four: column i of each tet's D_rest^-1 is contiguous (Eigen is column-major) and holds
// (a_1[i], a_2[i], a_3[i]), so one load per tet and a transpose give a_1[i], a_2[i] and a_3[i] for
// all four. The fourth float read belongs to the next column or to the constraint's compliance
// and is discarded.
template <typename T>
void strainWeightsOf(const StrainConstraint* c, VecOf<T> (&a)[4]) {
  if constexpr (kWidth<T> == 1) {
    const auto w = strainWeights(c[0].invRestShape);
    for (int k = 0; k < 4; ++k) a[k] = w[k];
  } else {
    Lane4 column[3][3][kGroups<T>];  // column[i][k][g] = a_{k+1}[i] of group g
    for (std::size_t g = 0; g < kGroups<T>; ++g) {
      // The matrices' floats, without calling Eigen here (lane_sweeps.h: no shared inline code).
      const auto* m = reinterpret_cast<const float(*)[9]>(&c[4 * g].invRestShape);
      const std::size_t stride = sizeof(StrainConstraint) / sizeof(float);
      static_assert(sizeof(StrainConstraint) % sizeof(float) == 0 && sizeof(Mat3) == 9 * sizeof(float));
      for (int i = 0; i < 3; ++i) {
        const float* col = *m + 3 * i;
        Lane4 r[4] = {load4(col), load4(col + stride), load4(col + 2 * stride), load4(col + 3 * stride)};
        transposeGroups(r);
        column[i][0][g] = r[0], column[i][1][g] = r[1], column[i][2][g] = r[2];
      }
    }
    for (int k = 0; k < 3; ++k) a[k + 1] = {concat<T>(column[0][k]), concat<T>(column[1][k]), concat<T>(column[2][k])};
    a[0] = -(a[1] + a[2] + a[3]);
  }
}

// The lanes of a strain batch: weights, the two coefficients, the six multipliers (component k of
// tet j at lambdas[k * tets + j], StrainLambdas) and, when damped, F at the start of the substep.
template <typename T>
struct StrainLanes {
  VecOf<T> a[4];
  XpbdCoefficientsT<T> stretch, shear;
  StrainLambdaT<T> lambda;
  VecOf<T> fStart[3];

  StrainLanes(const StrainConstraint* c, const float* lambdas, std::size_t tets, std::size_t first, std::size_t count,
              const ConstraintDamping& damping, float invH, const float* startDeformation) {
    const auto [stretchCompliance, shearCompliance] = fieldPairOf<T>(c, &StrainConstraint::stretchCompliance);
    stretch = XpbdCoefficientsT<T>::make(stretchCompliance, splat<T>(damping.strainStretch), invH);
    shear = XpbdCoefficientsT<T>::make(shearCompliance, splat<T>(damping.strainShear), invH);
    strainWeightsOf<T>(c, a);
    for (int k = 0; k < kStrainComponents; ++k) lambda[k] = loadLanes<T>(lambdas + k * tets + first, count);
    if (startDeformation) loadDeformation<T>(startDeformation, tets, first, count, fStart);
  }
  static void add(float* lambdas, std::size_t tets, std::size_t first, std::size_t count,
                  const StrainLambdaT<T>& dLambda) {
    for (int k = 0; k < kStrainComponents; ++k) addLanes<T>(lambdas + k * tets + first, dLambda[k], count);
  }
};

// F of tets [begin, end) at the start of the substep, into Body::startDeformation (`out`): the damped
// strain sweeps read it instead of the positions then.
template <typename T>
VRD_SWEEP void startDeformation(const StrainConstraint* constraints, std::size_t begin, std::size_t end, float* out,
                                std::size_t tets, const Range& r) {
  const auto batch = [&](std::size_t first, std::size_t count, const StrainConstraint* c) {
    const Gathered<T, 4, false> g(c, count, r.start, r.start);
    VecOf<T> a[4], f[3];
    strainWeightsOf<T>(c, a);
    deformationColumns(g.x, a, f);
    for (int i = 0; i < 3; ++i)
      for (int d = 0; d < 3; ++d) storeLanes<T>(out + std::size_t(3 * i + d) * tets + first, f[i][d], count);
  };
  forBatches<T>(begin, end, batch, constraints);
}

template <typename T, bool Damped>
VRD_SWEEP void strain(const StrainConstraint* constraints, std::size_t begin, std::size_t end, float* lambdas,
                      std::size_t tets, const ConstraintDamping& damping, const Range& r) {
  const auto batch = [&](std::size_t first, std::size_t count, const StrainConstraint* c) {
    Gathered<T, 4, false> g(c, count, r.pred, r.start);
    const StrainLanes<T> s(c, lambdas, tets, first, count, damping, r.invH, Damped ? r.startDeformation : nullptr);
    const auto out = solveStrainFromStart(g.x, g.w, s.a, s.lambda, s.stretch, s.shear, Damped ? s.fStart : nullptr);
    StrainLanes<T>::add(lambdas, tets, first, count, out.dLambda);
    g.move(out.dp);
    g.store(r.pred);
  };
  forBatches<T>(begin, end, batch, constraints);
}

// Strain and volume of the same tets in one pass (strain_volume.h): volume[j] belongs to strain[j].
template <typename T, bool Damped>
VRD_SWEEP void strainVolume(const StrainConstraint* strain, const VolumeConstraint* volume, std::size_t begin,
                            std::size_t end, float* strainLambdas, float* volumeLambdas, std::size_t tets,
                            const ConstraintDamping& damping, const Range& r) {
  const auto batch = [&](std::size_t first, std::size_t count, const StrainConstraint* c, const VolumeConstraint* v) {
    Gathered<T, 4, false> g(c, count, r.pred, r.start);
    const StrainLanes<T> s(c, strainLambdas, tets, first, count, damping, r.invH,
                           Damped ? r.startDeformation : nullptr);
    const auto [restVolume, compliance] = fieldPairOf<T>(v, &VolumeConstraint::restVolume);
    const auto k = XpbdCoefficientsT<T>::make(compliance, splat<T>(damping.volume), r.invH);
    const auto out = solveStrainVolume(g.x, g.w, s.a, s.lambda, s.stretch, s.shear, restVolume,
                                       loadLanes<T>(volumeLambdas + first, count), k, Damped ? s.fStart : nullptr);
    StrainLanes<T>::add(strainLambdas, tets, first, count, out.dLambdaStrain);
    addLanes<T>(volumeLambdas + first, out.dLambdaVolume, count);
    g.move(out.dp);
    g.store(r.pred);
  };
  forBatches<T>(begin, end, batch, strain, volume);
}

// The warm start (SolverSettings::warmStart) of tets [begin, end): each corner k moves by
// w_k sum_c lambda_c grad_k C_c of the tet's six strain multipliers, with the gradients where the
// last substep ended (r.start): grad_k C_ij = a_k[i] f_j + a_k[j] f_i (eq. 34), gathered as
// sum_i a_k[i] u_i.
template <typename T>
VRD_SWEEP void warmStrain(const StrainConstraint* constraints, std::size_t begin, std::size_t end, const float* lambdas,
                          std::size_t tets, const Range& r) {
  const auto batch = [&](std::size_t first, std::size_t count, const StrainConstraint* c) {
    Gathered<T, 4, true> g(c, count, r.pred, r.start);
    VecOf<T> a[4], f[3];
    strainWeightsOf<T>(c, a);
    deformationColumns(g.xStart, a, f);
    T l[kStrainComponents];  // 00, 11, 22, 01, 02, 12
    for (int k = 0; k < kStrainComponents; ++k) l[k] = loadLanes<T>(lambdas + k * tets + first, count);
    const T two = splat<T>(2.0f);
    const VecOf<T> u[3] = {two * l[0] * f[0] + l[3] * f[1] + l[4] * f[2], l[3] * f[0] + two * l[1] * f[1] + l[5] * f[2],
                           l[4] * f[0] + l[5] * f[1] + two * l[2] * f[2]};
    VecOf<T> dp[4];
    for (int k = 0; k < 4; ++k) dp[k] = g.w[k] * (a[k][0] * u[0] + a[k][1] * u[1] + a[k][2] * u[2]);
    g.move(dp);
    g.store(r.pred);
  };
  forBatches<T>(begin, end, batch, constraints);
}

// The same for volume constraints: w_k lambda grad_k C (eqs. 18-21) where the last substep ended.
template <typename T>
VRD_SWEEP void warmVolume(const VolumeConstraint* constraints, std::size_t begin, std::size_t end, const float* lambdas,
                          const Range& r) {
  const auto batch = [&](std::size_t first, std::size_t count, const VolumeConstraint* c) {
    Gathered<T, 4, true> g(c, count, r.pred, r.start);
    const auto e = evalVolume(g.xStart[0], g.xStart[1], g.xStart[2], g.xStart[3], splat<T>(0.0f));
    const T lambda = loadLanes<T>(lambdas + first, count);
    VecOf<T> dp[4];
    for (int k = 0; k < 4; ++k) dp[k] = (g.w[k] * lambda) * e.grad[k];
    g.move(dp);
    g.store(r.pred);
  };
  forBatches<T>(begin, end, batch, constraints);
}

// Bending, a level (BodyModel::bendLevels) at a time; flattened, as the other sweeps: evalBend and
// projectScalar as calls took 29% more time one at a time.
template <typename T, bool Damped>
VRD_SWEEP void bend(const BendConstraint* constraints, std::size_t begin, std::size_t end, float* lambdas, float tau,
                    const Range& r) {
  oneMultiplier<T, Damped, 4>(constraints, begin, end, lambdas, tau, r, &BendConstraint::restAngle,
                              [](const auto&... a) { return solveBend(a...); });
}

// Eq. 25's sums (shapeMatchSums) over particles [begin, end): with lanes, each product in double
// as there, in four double lanes per group of four particles, and the padded last batch's extra
// lanes massless (forBatches); the lanes are added in a fixed order, so the sums depend only on
// the range.
template <typename T>
VRD_SWEEP void shapeMatchSumsOf(const Point* p, const Vec3* q, const float* mass, std::size_t begin, std::size_t end,
                                ShapeMatchSums& out) {
  if constexpr (kWidth<T> == 1) {
    out = shapeMatchSums(p, q, mass, begin, end);
  } else {
    using Double4 = double __attribute__((vector_size(32)));
    Double4 sum[12] = {};  // sum_i m_i p_i, then A_pq column-major
    const auto batch = [&](std::size_t first, std::size_t count, const Point* points, const Vec3* offsets) {
      V3<T> x;
      T w;
      loadConsecutivePoints(points, x, w);
      const V3<T> o = loadVec3s<T>(offsets);
      Lane4 part[7][kGroups<T>];
      split(x.x, part[0]), split(x.y, part[1]), split(x.z, part[2]);
      split(o.x, part[3]), split(o.y, part[4]), split(o.z, part[5]);
      split(loadLanes<T>(mass + first, count), part[6]);  // 0 in the padding's lanes
      for (std::size_t g = 0; g < kGroups<T>; ++g) {
        Double4 v[7];
        for (int k = 0; k < 7; ++k) v[k] = __builtin_convertvector(part[k][g], Double4);
        const Double4 mp[3] = {v[6] * v[0], v[6] * v[1], v[6] * v[2]};
        for (int r = 0; r < 3; ++r) sum[r] += mp[r];
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) sum[3 + 3 * c + r] += mp[r] * v[3 + c];
      }
    };
    forBatches<T>(begin, end, batch, p, q);
    double* o = reinterpret_cast<double*>(&out.weighted);  // no Eigen call here (lane_sweeps.h)
    double* a = reinterpret_cast<double*>(&out.Apq);
    for (int k = 0; k < 12; ++k) (k < 3 ? o[k] : a[k - 3]) = ((sum[k][0] + sum[k][1]) + sum[k][2]) + sum[k][3];
  }
}

// Shape matching's goals (eq. 28) for particles [begin, end) of offsets q (ShapeMatchModel::
// restOffsets) and multipliers `lambda`, given the frame (eqs. 25-27) and, for the damping, the
// frame at the start of the substep: one at a time, or kWidth<T> consecutive particles at once and
// a last batch padded (as in forBatches), so that every particle gets the same arithmetic in
// whichever batch and lane it falls.
template <typename T>
VRD_SWEEP void shapeMatchParticles(const Vec3* q, float compliance, const ShapeMatchFrame& frame,
                                   const ShapeMatchFrame& startFrame, Vec3* lambda, float tau, const Range& r,
                                   std::size_t begin, std::size_t end) {
  if constexpr (kWidth<T> == 1) {
    const XpbdCoefficients k = XpbdCoefficients::make(compliance, tau, r.invH);
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 goal = frame.centroid + frame.rotation * q[i];
      const Vec3 change =
          tau > 0.0f
              ? Vec3((r.pred[i].pos - goal) - (r.start[i].pos - (startFrame.centroid + startFrame.rotation * q[i])))
              : Vec3::Zero();
      const Vec3 dLambda = solveShapeMatchParticle(r.pred[i], goal, lambda[i], k, change);
      lambda[i] += dLambda;
      r.pred[i].pos += r.pred[i].w * dLambda;
    }
  } else {
    constexpr std::size_t W = kWidth<T>;
    // No Eigen call here (lane_sweeps.h): R's floats column-major, then c2's.
    const auto goalsOf = [](const ShapeMatchFrame& f, const V3<T>& off) {
      const float* R = reinterpret_cast<const float*>(&f.rotation);
      const float* c = reinterpret_cast<const float*>(&f.centroid);
      return V3<T>{splat<T>(c[0]) + splat<T>(R[0]) * off.x + splat<T>(R[3]) * off.y + splat<T>(R[6]) * off.z,
                   splat<T>(c[1]) + splat<T>(R[1]) * off.x + splat<T>(R[4]) * off.y + splat<T>(R[7]) * off.z,
                   splat<T>(c[2]) + splat<T>(R[2]) * off.x + splat<T>(R[5]) * off.y + splat<T>(R[8]) * off.z};
    };
    const T alphaTilde = splat<T>(compliance * r.invH * r.invH), gamma = splat<T>(tau * r.invH), zero = splat<T>(0.0);
    // solveShapeMatchParticle for W particles; kinematic ones (w = 0) get no change.
    const auto batch = [&](Point* pred, const Point* start, const Vec3* offsets, Vec3* lambdas, std::size_t count) {
      V3<T> p, x;
      T w, ws;
      loadConsecutivePoints(pred, p, w);
      const V3<T> off = loadVec3s<T>(offsets), lambdaNow = loadVec3s<T>(lambdas);
      const V3<T> goal = goalsOf(frame, off);
      V3<T> change = V3<T>::Zero();  // of C = p - goal in the substep
      if (tau > 0.0f) loadConsecutivePoints(start, x, ws), change = (p - goal) - (x - goalsOf(startFrame, off));
      const T alphaTildeOf = alphaTilde * w;  // alpha_i = alpha / m_i
      const T invDenominator = 1.0f / ((1.0f + gamma) * w + alphaTildeOf);
      const V3<T> d = (goal - p - alphaTildeOf * lambdaNow - gamma * change) * invDenominator;
      const auto moves = w > zero;
      const V3<T> dLambda = {select(moves, d.x, zero), select(moves, d.y, zero), select(moves, d.z, zero)};
      storeVec3s<T>(lambdas, lambdaNow + dLambda);
      storeConsecutivePoints(pred, p + w * dLambda, w, count);
    };
    std::size_t i = begin;
    for (; i + W <= end; i += W) batch(r.pred + i, r.start + i, q + i, lambda + i, W);
    if (i == end) return;
    // The rest on copies padded with the first of them; only the real ones are copied back.
    alignas(16) float pred[4 * W], start[4 * W], offsets[3 * W], lambdas[3 * W];
    const std::size_t count = end - i;
    for (std::size_t l = 0; l < W; ++l) {
      const std::size_t from = i + (l < count ? l : 0);
      std::memcpy(pred + 4 * l, floats(r.pred + from), 4 * sizeof(float));
      std::memcpy(start + 4 * l, floats(r.start + from), 4 * sizeof(float));
      std::memcpy(offsets + 3 * l, q + from, 3 * sizeof(float));
      std::memcpy(lambdas + 3 * l, lambda + from, 3 * sizeof(float));
    }
    const auto points = [](float* f) { return reinterpret_cast<Point*>(f); };
    const auto vectors = [](float* f) { return reinterpret_cast<Vec3*>(f); };
    batch(points(pred), points(start), vectors(offsets), vectors(lambdas), count);
    std::memcpy(floats(r.pred + i), pred, count * sizeof(Point));
    std::memcpy(static_cast<void*>(lambda + i), lambdas, count * sizeof(Vec3));
  }
}

}  // namespace vrd::sweeps
