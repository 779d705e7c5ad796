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

/// How many constraints of one colour the solver projects at once (constraint_colouring.h).
enum class SimdLevel : std::uint8_t {
  Off,     ///< one at a time: the plain reference loops
  Sse,     ///< 4 lanes (SSE on every x86-64, NEON on aarch64)
  Avx2,    ///< 8 lanes (AVX2 + FMA; x86-64 only)
  Avx512,  ///< 16 lanes (AVX-512F; x86-64 only)
  Best,    ///< the widest this CPU has (checked at run time)
};

/// Whether this CPU can run `level` (Off, Sse and Best always can).
bool cpuSupports(SimdLevel level);
/// `level` with Best replaced by the widest level this CPU supports.
SimdLevel resolveSimd(SimdLevel level);
const char* simdName(SimdLevel level);  ///< "off", "sse", "avx2", "avx512" or "best"

struct SolverSettings {
  /// dt of one step (s); the paper uses 1/60. In double so that step k's time, k dt, is exact
  /// over hours (the solver works in float substeps).
  double timeStep = 1.0 / 60.0;
  int substeps = 1;    ///< n: each step runs n substeps of h = dt/n ("small steps")
  int iterations = 5;  ///< Gauss-Seidel iterations per substep; the paper uses 5
  Vec3 gravity{0.0f, -9.81f, 0.0f};
  /// Velocity damping c (1/s): v *= max(0, 1 - c h) each substep, applied before gravity so a body
  /// at rest still weighs m g (docs/validation.md P4).
  float linearDamping = 0.0f;
  NanPolicy onNan = NanPolicy::Freeze;
  bool timeStages = true;  ///< record per-stage wall-clock times (a few dozen clock reads per step)
  /// Lanes for each colour's constraints: the same Gauss-Seidel sweep as Off, up to rounding.
  SimdLevel simd = SimdLevel::Best;
  /// Solver threads (src/sim/solver_team.h): 2 sweep the halves of a big body at once, more share each colour;
  /// the result does not depend on it. Worth it for bodies of several thousand tets: a world with
  /// no body of 4,096 or more constraints of one type runs on the calling thread alone, as does 1.
  /// kAutoThreads: two where the machine has two hardware threads or more (solverThreads()).
  int threads = kAutoThreads;
  static constexpr int kAutoThreads = 0;
  /// With more than one thread, a step runs on the calling thread alone while that has lately been
  /// faster than the team (a machine busier than its cores; the result is the same). false: always
  /// the team.
  bool threadsFallBack = true;
  /// Projects a tet's strain and volume constraints together, in one pass over the tets
  /// (strain_volume.h), instead of all strain constraints and then all volume ones as the paper
  /// does. Both are Gauss-Seidel orders with the same fixed points; the pass reads and writes each
  /// tet's particles once and costs about as much as the strain pass alone. Off: the paper's
  /// order, timed as Stage::Strain and Stage::Volume (its Table 1) instead of Stage::StrainVolume.
  bool fuseStrainVolume = true;
  /// Measure how far each step's solve is from converged: every constraint type's corrections in
  /// the last iteration (StepReport::residuals). Costs a copy of the bodies' positions per type,
  /// once per step.
  bool measureResiduals = false;
  /// Adaptive budget: > 0 iterates each substep until no constraint type corrects any particle by
  /// more than `tolerance` (relative to its body's mean rest edge) in an iteration, at most
  /// `iterations` times; the step reports how many it ran. 0: always `iterations`.
  float tolerance = 0.0f;
  /// Starts each substep's solve from the last substep's multipliers instead of from zero
  /// (Algorithm 1, line 9): the bodies' and the contacts found again keep theirs, and each
  /// prediction moves by w grad C^T lambda of them first. A body at rest, or held still by a
  /// fingertip, is then a fixed point of any number of iterations, so its multipliers and the
  /// forces read from them (lambda / h^2) are the converged ones. Not for bodies whose substep is
  /// stiff for their mass (hard or nearly incompressible constraints on light particles, cloth):
  /// the solve can diverge there (docs/haptics.md). false: the paper's cold start.
  bool warmStart = false;

  float substepSize() const { return float(timeStep / substeps); }
};

/// Throws vrd::Error for a non-positive or non-finite time step, substeps or iterations < 1,
/// non-finite gravity, negative damping, threads outside [1, 256] or SIMD this CPU lacks.
void validateSolverSettings(const SolverSettings& settings);

/// The threads a world with these settings solves with: `threads`, kAutoThreads resolved.
int solverThreads(const SolverSettings& settings);

}  // namespace vrd
