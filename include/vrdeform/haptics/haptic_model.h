#pragma once
// The haptic force model (Algorithm 2, lines 24-42), read from a world after each step.
//
// It gives the paper's single value for the hand and, beyond the paper, one value per fingertip:
// the same equations with that finger's own contacts (eq. 40) and its own position as the centre
// of the inverse-distance weights (eq. 43), so a finger that pushes feels it and one in the air
// does not. Next to each normalised value it gives the contact force in newtons (lambda / h^2)
// and the condition B baseline. Every output is finite and in [0, 1] (newtons: finite, >= 0).

#include <array>
#include <vector>

#include "vrdeform/haptics/baseline.h"
#include "vrdeform/haptics/haptic_signal.h"
#include "vrdeform/interact/grasp.h"
#include "vrdeform/interact/hand_rig.h"

namespace vrd {

struct HapticSettings {
  HapticSignalSettings signal;  ///< eqs. 40-44 (calibrate the tau with calibrateHaptics())
  BaselineSettings baseline;
  /// Largest change of a normalised output per millisecond of simulated time: full scale takes at
  /// least 1 / maxChangePerMs ms. Infinity switches the limit off.
  float maxChangePerMs = 0.05f;
};

/// Throws vrd::Error for a non-positive tau, a beta outside [0, 1], beta_v + beta_s != 1, a
/// negative epsilon, alpha_t outside (0, 1] or a non-positive change limit.
void validateHapticSettings(const HapticSettings& settings);

struct FingerHaptics {
  float force = 0.0f;        ///< actuator value in [0, 1]: eq. 44 smoothing, then the change limit
  float raw = 0.0f;          ///< the finger's F_raw (eq. 43)
  float newtons = 0.0f;      ///< magnitude of the force between fingertip and body (N)
  float baseline = 0.0f;     ///< condition B value in [0, 1]
  std::size_t contacts = 0;  ///< contacts that pushed in the last substep
  /// Indentation (m): how far the fingertip has gone into the body since this touch began, along
  /// the direction of its first push (the surface's normal there; a slide across it does not
  /// count); 0 in the air.
  float depth = 0.0f;
};

struct HapticFrame {
  float paper = 0.0f;     ///< Algorithm 2's F_out for the whole hand (one value for every actuator)
  float paperRaw = 0.0f;  ///< its F_raw (eq. 43)
  std::array<FingerHaptics, kFingerCount> fingers{};
};

class HapticModel {
 public:
  explicit HapticModel(const HapticSettings& settings = {});

  /// Reads the last step's multipliers and advances the outputs by one step.
  const HapticFrame& update(const World& world, const HandRig& rig, const Grasp& grasp);
  const HapticFrame& frame() const { return frame_; }
  const HapticSettings& settings() const { return settings_; }
  /// Zeroes the outputs (e.g. when the session stops or the glove reconnects).
  void reset() { frame_ = {}, touches_ = {}; }

 private:
  void gatherTets(const World& world);
  float inverseDistanceSignal(const Vec3& centre) const;

  HapticSettings settings_;
  HapticFrame frame_;
  struct Touch {
    bool began = false;
    Vec3 at = Vec3::Zero();     // the fingertip's centre when it began
    Vec3 along = Vec3::Zero();  // its first push's direction (zero until it pushed)
  };
  std::array<Touch, kFingerCount> touches_{};
  TetSignals tets_;  // every tet of every active body, this step
};

}  // namespace vrd
