#pragma once
// What the simulation loop publishes after each step for viewers (desktop, VR server): particle
// positions, the hand, the haptic signal and the step's timings; and the channel that hands the
// newest one to one reader without either side ever waiting for the other.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/metrics/stage_times.h"

namespace vrd {

class HapticSession;

/// The world after one step of a SimulationLoop.
struct Snapshot {
  std::uint64_t step = 0;                ///< steps the loop had run, this one included; 0: none yet
  double time = 0.0;                     ///< simulated time since the loop started (s), end of this step
  std::vector<Vec3> positions;           ///< every particle of the world, in world order
  std::vector<std::uint32_t> bodyFirst;  ///< first particle of each body (BodyId order)
  /// |net force of the body's own constraints| on each particle (N, World::particleMaterialForces),
  /// in world order: only when asked for (captureConstraintForces, SimulationLoop::setConstraintForces);
  /// empty otherwise.
  std::vector<float> constraintForce;
  /// Fingertip centres; zero where !fingerPresent.
  std::array<Vec3, kFingerCount> fingertips{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  std::array<bool, kFingerCount> fingerPresent{};  ///< fingers the hand has; none without a hand
  float fingertipRadius = 0.0f;                    ///< radius of every fingertip sphere (m); 0 without a hand
  HapticFrame haptics;                             ///< the haptic model's outputs after this step
  bool grasping = false;                           ///< a grasp is holding the body
  bool contact = false;                            ///< a finger touches or a grasp holds (the latency phase)
  StageTimes times;                                ///< per-stage times of this step
  std::array<Residual, kStageCount> residuals;     ///< how converged this step was (StepReport::residuals)
  int iterations = 0;                              ///< Gauss-Seidel iterations this step ran
  double stepWallMs = 0.0;                         ///< wall time of input, simulation and outputs (ms)
};

/// Fills `s` with `world` as it is after its `step`-th step (1-based), at simulated time `time`, and
/// `session`'s hand and haptic signal (none when null): what the loop publishes, also usable by a
/// caller that steps the world itself (headless rendering). Reuses the vectors' capacity.
void captureSnapshot(Snapshot& s, const World& world, const HapticSession* session, std::uint64_t step, double time,
                     double stepWallMs = 0.0);

/// Fills `s.constraintForce` from `world`'s last substep (World::particleMaterialForces): about
/// the cost of one solver iteration, so the loop does it only for a reader that shows it.
void captureConstraintForces(Snapshot& s, const World& world);

/// A triple buffer from the loop thread to one reader. The writer fills back() and publish()es it;
/// the reader's update() swaps in the newest published slot. Each side owns one slot, the third
/// is exchanged through one atomic, so both sides are wait-free and a reader that stops reading
/// costs the writer nothing: it keeps overwriting the middle slot. Slots keep their vectors'
/// capacity, so the writer stops allocating once each slot has been filled (or at once, when
/// constructed with the sizes).
class SnapshotChannel {
 public:
  /// Reserves every slot for `particles` particles and `bodies` bodies.
  explicit SnapshotChannel(std::size_t particles = 0, std::size_t bodies = 0);
  SnapshotChannel(const SnapshotChannel&) = delete;
  SnapshotChannel& operator=(const SnapshotChannel&) = delete;

  // --- Writer (one thread) --------------------------------------------------------------------
  /// The slot to fill next; it holds an older snapshot (not necessarily the last one published).
  Snapshot& back() { return slots_[back_]; }
  /// Makes back() the newest snapshot, replacing one the reader has not taken yet.
  void publish();

  // --- Reader (one thread) --------------------------------------------------------------------
  /// Takes the newest published snapshot, if one arrived since the last call; returns whether one did.
  bool update();
  /// The snapshot the last update() took (step 0 before any); unchanged until the next update().
  const Snapshot& front() const { return slots_[front_]; }
  /// update() and, when something new arrived, copies it into `out` (reusing its capacity).
  bool read(Snapshot& out);

 private:
  static constexpr unsigned kIndex = 3;     // the slot index bits of middle_
  static constexpr unsigned kFresh = 4;     // middle_ holds a slot the reader has not taken
  static constexpr std::size_t kLine = 64;  // keeps each side's index off the other's cache line

  std::array<Snapshot, 3> slots_;
  alignas(kLine) std::atomic<unsigned> middle_{1};
  alignas(kLine) unsigned back_ = 2;   // the writer's
  alignas(kLine) unsigned front_ = 0;  // the reader's
};

}  // namespace vrd
