#pragma once
// Wall-clock time spent in each stage of a simulation step (paper Tables 1 and 3).

#include <array>
#include <chrono>
#include <cstdint>
#include <string_view>

namespace vrd {

enum class Stage : std::uint8_t {
  Predict,        ///< forces, damping and predicted positions (Algorithm 1, lines 6-8)
  Detect,         ///< collider, fingertip and body contact detection, and the multipliers zeroed (lines 9-11)
  Distance,       ///< stretch constraints
  Volume,         ///< tet volume constraints
  Strain,         ///< tet strain constraints
  StrainVolume,   ///< tet strain and volume constraints in one pass (SolverSettings::fuseStrainVolume)
  Bend,           ///< dihedral bending constraints
  ShapeMatching,  ///< global shape matching
  Attachment,     ///< attachments
  Contact,        ///< collider contacts with friction
  Fingertip,      ///< fingertip contacts
  BodyContact,    ///< contacts between bodies and of a body with itself (detected under Detect)
  Finalise,       ///< velocity update, commit, NaN check (lines 18-21)
  Interact,       ///< hand input and grasp (Algorithm 2, lines 3-10), measured by a haptic session
  Force,          ///< haptic force model (Algorithm 2, lines 24-41), measured by a haptic session
  Count
};

inline constexpr std::size_t kStageCount = std::size_t(Stage::Count);

std::string_view stageName(Stage stage);

/// Milliseconds per stage, summed over the substeps and iterations of one step.
struct StageTimes {
  std::array<double, kStageCount> ms{};

  double& operator[](Stage s) { return ms[std::size_t(s)]; }
  double operator[](Stage s) const { return ms[std::size_t(s)]; }
  double solveMs() const;  ///< all constraint stages
  double totalMs() const;
};

/// Adds the time between construction and destruction to one stage; does nothing when disabled.
class StageTimer {
 public:
  StageTimer(StageTimes& times, Stage stage, bool enabled)
      : slot_(enabled ? &times[stage] : nullptr), start_(enabled ? Clock::now() : Clock::time_point{}) {}
  ~StageTimer() {
    if (slot_) *slot_ += std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  double* slot_;
  Clock::time_point start_;
};

}  // namespace vrd
