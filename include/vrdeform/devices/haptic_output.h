#pragma once
// Where the haptic signal goes besides the glove: one sample per simulation step (time, per-finger
// values, the paper's hand value) handed to any number of outputs (CSV recorder, OSC over UDP,
// the WEART client). An output never passes on a NaN or a normalised value outside [0, 1]:
// every implementation emits sanitised(sample).

#include <array>
#include <cmath>
#include <string_view>

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/hand.h"

namespace vrd {

/// One step of the haptic signal as outputs see it. Finger order: thumb, index, middle, ring, little.
struct HapticSample {
  double time = 0.0;                          ///< simulation time (s)
  std::array<float, kFingerCount> force{};    ///< per finger actuator value, normalised to [0, 1]
  std::array<float, kFingerCount> newtons{};  ///< per finger contact force (N), finite and >= 0
  float paper = 0.0f;                         ///< Algorithm 2's single value for the hand, [0, 1]
  std::array<bool, kFingerCount> present{};   ///< fingers the hand has (G1: thumb, index, middle)
};

/// A force in newtons as outputs emit it: finite and >= 0 (a magnitude), anything else reads as 0.
inline float clampNewtons(float v) { return std::isfinite(v) && v > 0.0f ? v : 0.0f; }

/// The sample an output emits for `sample`: normalised values through clampUnit (math/types.h), newtons through
/// clampNewtons, zeros for absent fingers, a non-finite time read as 0.
HapticSample sanitised(const HapticSample& sample);

/// The sample for one step of a HapticModel: each present finger's force and newtons (zeros for
/// absent fingers) and the paper's value, sanitised.
HapticSample sampleOf(double time, const HapticFrame& frame, const std::array<bool, kFingerCount>& present);

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

}  // namespace vrd
