#pragma once
// Where the haptic signal goes besides the glove: one sample per simulation step (time, per-finger
// values, the paper's hand value) handed to any number of outputs (CSV recorder, OSC over UDP,
// the WEART client). An output never passes on a NaN or a normalised value outside [0, 1]:
// every implementation emits sanitised(sample).

#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/hand.h"

namespace vrd {

class HapticSession;

/// One step of the haptic signal as outputs see it: what the glove gets (force, paper) and what a
/// study logs beside it. Finger order: thumb, index, middle, ring, little; absent fingers read 0.
struct HapticSample {
  std::uint64_t step = 0;                              ///< steps done when it was taken (1 after the first)
  double time = 0.0;                                   ///< simulation time (s): step x dt
  std::array<float, kFingerCount> force{};             ///< per finger actuator value, normalised to [0, 1]
  std::array<float, kFingerCount> newtons{};           ///< per finger contact force (N), finite and >= 0
  std::array<float, kFingerCount> raw{};               ///< per finger F_raw before smoothing (eq. 43), [0, 1]
  std::array<float, kFingerCount> baseline{};          ///< per finger condition B value, [0, 1]
  std::array<float, kFingerCount> depth{};             ///< per finger indentation (m, FingerHaptics::depth)
  std::array<std::uint32_t, kFingerCount> contacts{};  ///< per finger contacts that pushed
  std::array<Vec3, kFingerCount> tip{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(),
                                     Vec3::Zero()};  ///< fingertip centres (m), world frame
  float paper = 0.0f;                                ///< Algorithm 2's single value for the hand, [0, 1]
  float paperRaw = 0.0f;                             ///< its F_raw (eq. 43), [0, 1]
  bool grasp = false;                                ///< a grasp holds the body
  std::array<bool, kFingerCount> present{};          ///< fingers the hand has (G1: thumb, index, middle)
};

/// A force in newtons as outputs emit it: finite and >= 0 (a magnitude), anything else reads as 0.
inline float clampNewtons(float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; }

/// The sample an output emits for `sample`: normalised values through clampUnit (math/types.h), newtons through
/// clampNewtons, zeros for absent fingers, a non-finite time read as 0.
HapticSample sanitised(const HapticSample& sample);

/// The sample of a HapticModel's frame after `step` steps of `dt`: each present finger's values
/// (zeros for absent fingers, no fingertip positions) and the paper's, sanitised.
HapticSample sampleOf(std::uint64_t step, double dt, const HapticFrame& frame,
                      const std::array<bool, kFingerCount>& present);
/// The same for a session after `step` steps, with the fingertip positions and the grasp state.
HapticSample sampleOf(std::uint64_t step, const HapticSession& session);

/// A destination for the haptic signal. Implementations are used from one thread at a time; send()
/// never throws (I/O errors are counted and reported by the implementation) and never blocks for long.
class HapticOutput {
 public:
  virtual ~HapticOutput() = default;
  /// Emits one step of the signal.
  virtual void send(const HapticSample& sample) = 0;
  /// Zeroes every output, e.g. at shutdown or on a watchdog trip.
  virtual void release() = 0;
};

/// Passes each sample on to `inner` with the condition B baseline in place of the force: the glove
/// of a study's baseline condition gets the vendor-style signal.
class BaselineAsForce final : public HapticOutput {
 public:
  explicit BaselineAsForce(HapticOutput& inner) : inner_(inner) {}
  void send(const HapticSample& sample) override {
    HapticSample s = sample;
    s.force = s.baseline;
    inner_.send(s);
  }
  void release() override { inner_.release(); }

 private:
  HapticOutput& inner_;
};

}  // namespace vrd
