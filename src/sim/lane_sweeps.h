#pragma once
// The sweeps (sweeps.h) of one width behind plain function pointers, so that the world picks the
// widest lanes the CPU has at run time (SolverSettings::simd). Each width is compiled in its own
// translation unit with its instruction set's flags (sweeps_sse.cpp: float and Lane4 with the
// default flags; x86/sweeps_avx2.cpp: Lane8; x86/sweeps_avx512.cpp: Lane16, on x86-64 only), and each of those
// instantiates the sweeps for its own lane type only: a template instantiated in two of them with
// different flags could be merged by the linker into the one that needs the newer CPU.

#include "sweeps.h"
#include "vrdeform/sim/solver_settings.h"

namespace vrd::sweeps {

/// Each function projects constraints [begin, end), which must be independent unless width is 1,
/// `width` at a time; a last batch of fewer than `width` fills the rest of its lanes with padding.
struct LaneSweeps {
  std::size_t width;
  void (*distance)(const DistanceConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau,
                   bool damped, const Range& r);
  void (*volume)(const VolumeConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
                 const Range& r);
  void (*bend)(const BendConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
               const Range& r);
  /// lambda: StrainLambdas::data() of `tets` tets
  void (*strain)(const StrainConstraint* c, std::size_t begin, std::size_t end, float* lambda, std::size_t tets,
                 const ConstraintDamping& damping, bool damped, const Range& r);
  /// F of `tets` tets at the start of the substep into `out` (Body::startDeformation)
  void (*startDeformation)(const StrainConstraint* c, std::size_t begin, std::size_t end, float* out, std::size_t tets,
                           const Range& r);
  /// strain and volume of the same `tets` tets in one pass (strain_volume.h)
  void (*strainVolume)(const StrainConstraint* strain, const VolumeConstraint* volume, std::size_t begin,
                       std::size_t end, float* strainLambda, float* volumeLambda, std::size_t tets,
                       const ConstraintDamping& damping, bool damped, const Range& r);
  /// the warm start's moves of `tets` tets' strain multipliers, and of volume multipliers
  void (*warmStrain)(const StrainConstraint* c, std::size_t begin, std::size_t end, const float* lambda,
                     std::size_t tets, const Range& r);
  void (*warmVolume)(const VolumeConstraint* c, std::size_t begin, std::size_t end, const float* lambda,
                     const Range& r);
  /// eq. 25's sums over particles [begin, end)
  void (*shapeMatchSums)(const Point* p, const Vec3* restOffsets, const float* mass, std::size_t begin, std::size_t end,
                         ShapeMatchSums& out);
  /// shape matching's goals (eq. 28) for particles [begin, end); `start`: the frame at the start of
  /// the substep (damping)
  void (*shapeMatch)(const Vec3* restOffsets, float compliance, const ShapeMatchFrame& frame,
                     const ShapeMatchFrame& start, Vec3* lambda, float tau, const Range& r, std::size_t begin,
                     std::size_t end);
};

template <typename T>
LaneSweeps makeLaneSweeps() {
  return {
      kWidth<T>,
      [](const DistanceConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
         const Range& r) {
        damped ? distance<T, true>(c, begin, end, lambda, tau, r) : distance<T, false>(c, begin, end, lambda, tau, r);
      },
      [](const VolumeConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
         const Range& r) {
        damped ? volume<T, true>(c, begin, end, lambda, tau, r) : volume<T, false>(c, begin, end, lambda, tau, r);
      },
      [](const BendConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
         const Range& r) {
        damped ? bend<T, true>(c, begin, end, lambda, tau, r) : bend<T, false>(c, begin, end, lambda, tau, r);
      },
      [](const StrainConstraint* c, std::size_t begin, std::size_t end, float* lambda, std::size_t tets,
         const ConstraintDamping& damping, bool damped, const Range& r) {
        damped ? strain<T, true>(c, begin, end, lambda, tets, damping, r)
               : strain<T, false>(c, begin, end, lambda, tets, damping, r);
      },
      [](const StrainConstraint* c, std::size_t begin, std::size_t end, float* out, std::size_t tets, const Range& r) {
        startDeformation<T>(c, begin, end, out, tets, r);
      },
      [](const StrainConstraint* s, const VolumeConstraint* v, std::size_t begin, std::size_t end, float* strainLambda,
         float* volumeLambda, std::size_t tets, const ConstraintDamping& damping, bool damped, const Range& r) {
        damped ? strainVolume<T, true>(s, v, begin, end, strainLambda, volumeLambda, tets, damping, r)
               : strainVolume<T, false>(s, v, begin, end, strainLambda, volumeLambda, tets, damping, r);
      },
      warmStrain<T>,
      warmVolume<T>,
      shapeMatchSumsOf<T>,
      shapeMatchParticles<T>,
  };
}

const LaneSweeps& scalarSweeps();  ///< one at a time (sweeps_sse.cpp)
const LaneSweeps& sseSweeps();     ///< 4 lanes (sweeps_sse.cpp)
const LaneSweeps& avx2Sweeps();    ///< 8 lanes (x86/sweeps_avx2.cpp); only where cpuSupports(SimdLevel::Avx2)
const LaneSweeps& avx512Sweeps();  ///< 16 lanes (x86/sweeps_avx512.cpp); only where cpuSupports(SimdLevel::Avx512)

/// The lane widths for `level`, widest first (SimdLevel::Off: one at a time). A colour runs in
/// whole batches of the widest and ends with one partial batch of the narrowest that holds the rest.
struct LanePlan {
  const LaneSweeps* widths[3] = {};
  std::size_t count = 0;

  /// Projects [begin, end) of one colour; `project(sweeps, begin, end)` calls the array's sweep.
  template <typename Project>
  void run(std::size_t begin, std::size_t end, Project project) const {
    const std::size_t whole = begin + (end - begin) / widths[0]->width * widths[0]->width;
    if (begin < whole) project(*widths[0], begin, whole);
    if (whole == end) return;
    std::size_t w = count - 1;
    while (widths[w]->width < end - whole) --w;
    project(*widths[w], whole, end);
  }
};
LanePlan lanePlan(SimdLevel level);

}  // namespace vrd::sweeps
