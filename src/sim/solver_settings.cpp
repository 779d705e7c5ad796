#include "vrdeform/sim/solver_settings.h"

#include <fmt/format.h>

#include "vrdeform/error.h"

namespace vrd {

void validateSolverSettings(const SolverSettings& s) {
  if (!(std::isfinite(s.timeStep) && s.timeStep > 0.0f))
    throw Error(fmt::format("solver: time step must be positive, got {}", s.timeStep));
  if (s.substeps < 1) throw Error(fmt::format("solver: substeps must be >= 1, got {}", s.substeps));
  if (s.iterations < 1) throw Error(fmt::format("solver: iterations must be >= 1, got {}", s.iterations));
  if (!isFinite(s.gravity)) throw Error("solver: gravity must be finite");
  if (!(std::isfinite(s.linearDamping) && s.linearDamping >= 0.0f))
    throw Error(fmt::format("solver: linear damping must be finite and >= 0, got {}", s.linearDamping));
}

}  // namespace vrd
