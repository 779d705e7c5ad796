#include "vrdeform/sim/solver_settings.h"

#include <fmt/format.h>

#include <cmath>
#include <iterator>
#include <thread>

#include "vrdeform/error.h"

namespace vrd {

bool cpuSupports(SimdLevel level) {
  switch (level) {
#ifdef VRDEFORM_X86_LANES
    case SimdLevel::Avx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case SimdLevel::Avx512:
      return __builtin_cpu_supports("avx512f");
#else
    case SimdLevel::Avx2:
    case SimdLevel::Avx512:
      return false;  // x86-64 only
#endif
    default:
      return true;
  }
}

SimdLevel resolveSimd(SimdLevel level) {
  if (level != SimdLevel::Best) return level;
  return cpuSupports(SimdLevel::Avx512) ? SimdLevel::Avx512
         : cpuSupports(SimdLevel::Avx2) ? SimdLevel::Avx2
                                        : SimdLevel::Sse;
}

const char* simdName(SimdLevel level) {
  constexpr const char* kNames[] = {"off", "sse", "avx2", "avx512", "best"};
  return std::size_t(level) < std::size(kNames) ? kNames[std::size_t(level)] : "unknown";
}

void validateSolverSettings(const SolverSettings& s) {
  if (!(std::isfinite(s.timeStep) && s.timeStep > 0.0))
    throw Error(fmt::format("solver: time step must be positive, got {}", s.timeStep));
  if (s.substeps < 1) throw Error(fmt::format("solver: substeps must be >= 1, got {}", s.substeps));
  if (s.iterations < 1) throw Error(fmt::format("solver: iterations must be >= 1, got {}", s.iterations));
  if (!isFinite(s.gravity)) throw Error("solver: gravity must be finite");
  if (!(std::isfinite(s.linearDamping) && s.linearDamping >= 0.0f))
    throw Error(fmt::format("solver: linear damping must be finite and >= 0, got {}", s.linearDamping));
  if (!(std::isfinite(s.tolerance) && s.tolerance >= 0.0f))
    throw Error(fmt::format("solver: tolerance must be finite and >= 0, got {}", s.tolerance));
  if (s.threads < 0 || s.threads > 256)
    throw Error(fmt::format("solver: threads must be in [1, 256] or kAutoThreads (0), got {}", s.threads));
  if (std::size_t(s.simd) > std::size_t(SimdLevel::Best)) throw Error("solver: unknown SIMD level");
  if (!cpuSupports(s.simd)) throw Error(fmt::format("solver: this CPU cannot run SIMD level {}", simdName(s.simd)));
}

int solverThreads(const SolverSettings& s) {
  if (s.threads != SolverSettings::kAutoThreads) return s.threads;
  return std::thread::hardware_concurrency() >= 2 ? 2 : 1;
}

}  // namespace vrd
