#pragma once
// Settings of the XPBD solver (Algorithm 1), separate from the world's state.

#include <cstdint>

#include "vrdeform/math/types.h"

namespace vrd {

/// What happens to a body in which a non-finite position or velocity appears.
enum class NanPolicy : std::uint8_t {
  Freeze,  ///< restore its last finite state, zero its velocity and stop simulating it
  Reset,   ///< put it back at rest in its initial pose and keep simulating
};

struct SolverSettings {
  float timeStep = 1.0f / 60.0f;  ///< dt of one step (s); the paper uses 1/60
  int substeps = 1;               ///< n: each step runs n substeps of h = dt/n ("small steps")
  int iterations = 5;             ///< Gauss-Seidel iterations per substep; the paper uses 5
  Vec3 gravity{0.0f, -9.81f, 0.0f};
  /// Velocity damping c (1/s): v *= max(0, 1 - c h) each substep, applied before gravity so a body
  /// at rest still weighs m g (validation.md P4).
  float linearDamping = 0.0f;
  NanPolicy onNan = NanPolicy::Freeze;
  bool timeStages = true;  ///< record per-stage wall-clock times (a few dozen clock reads per step)
  /// Project independent constraints four at a time in SIMD lanes (the same Gauss-Seidel sweep, up
  /// to rounding); off runs the plain one-at-a-time loops, the reference.
  bool simd = true;

  float substepSize() const { return timeStep / float(substeps); }
};

/// Throws vrd::Error for a non-positive or non-finite time step, substeps or iterations < 1,
/// non-finite gravity or negative damping.
void validateSolverSettings(const SolverSettings& settings);

}  // namespace vrd
