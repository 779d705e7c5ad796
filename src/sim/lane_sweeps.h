#pragma once
// The sweeps (sweeps.h) of one width behind plain function pointers, so that the world picks the
// widest lanes the CPU has at run time (SolverSettings::simd). Each width is compiled in its own
// translation unit with its instruction set's flags (sweeps_sse.cpp: float and Lane4 with the
// default flags; sweeps_avx2.cpp: Lane8; sweeps_avx512.cpp: Lane16), and each of those
// instantiates the sweeps for its own lane type only: a template instantiated in two of them with
// different flags could be merged by the linker into the one that needs the newer CPU.

#include "sweeps.h"
#include "vrdeform/sim/solver_settings.h"

namespace vrd::sweeps {

/// Each function projects constraints [begin, end), which must be independent unless width is 1,
/// `width` at a time, and returns where it stopped: the last (end - begin) % width are left for
/// narrower lanes.
struct LaneSweeps {
  std::size_t width;
  std::size_t (*distance)(const DistanceConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau,
                          bool damped, const Range& r);
  std::size_t (*volume)(const VolumeConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau,
                        bool damped, const Range& r);
  std::size_t (*strain)(const StrainConstraint* c, std::size_t begin, std::size_t end, StrainLambda* lambda,
                        const ConstraintDamping& damping, bool damped, const Range& r);
};

template <typename T>
LaneSweeps makeLaneSweeps() {
  constexpr std::size_t W = kWidth<T>;
  return {
      W,
      [](const DistanceConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
         const Range& r) {
        const std::size_t stop = begin + (end - begin) / W * W;
        damped ? distance<T, true>(c, begin, stop, lambda, tau, r) : distance<T, false>(c, begin, stop, lambda, tau, r);
        return stop;
      },
      [](const VolumeConstraint* c, std::size_t begin, std::size_t end, float* lambda, float tau, bool damped,
         const Range& r) {
        const std::size_t stop = begin + (end - begin) / W * W;
        damped ? volume<T, true>(c, begin, stop, lambda, tau, r) : volume<T, false>(c, begin, stop, lambda, tau, r);
        return stop;
      },
      [](const StrainConstraint* c, std::size_t begin, std::size_t end, StrainLambda* lambda,
         const ConstraintDamping& damping, bool damped, const Range& r) {
        const std::size_t stop = begin + (end - begin) / W * W;
        damped ? strain<T, true>(c, begin, stop, lambda, damping, r)
               : strain<T, false>(c, begin, stop, lambda, damping, r);
        return stop;
      },
  };
}

const LaneSweeps& scalarSweeps();  ///< one at a time (sweeps_sse.cpp)
const LaneSweeps& sseSweeps();     ///< 4 lanes (sweeps_sse.cpp)
const LaneSweeps& avx2Sweeps();    ///< 8 lanes (sweeps_avx2.cpp); only where cpuSupports(SimdLevel::Avx2)
const LaneSweeps& avx512Sweeps();  ///< 16 lanes (sweeps_avx512.cpp); only where cpuSupports(SimdLevel::Avx512)

/// The sweeps a colour runs through for `level`, widest first; always ends with scalarSweeps().
struct LanePlan {
  const LaneSweeps* widths[3] = {};
  std::size_t count = 0;
};
LanePlan lanePlan(SimdLevel level);

}  // namespace vrd::sweeps
