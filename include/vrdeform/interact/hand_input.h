#pragma once
// Where the hand comes from, one HandFrame per simulation step: a glove, a tracked hand, a script or
// a recorded session. The loop asks by step number and time, so a source may follow either clock.

#include <cstdint>

#include "vrdeform/interact/hand.h"

namespace vrd {

class HandInput {
 public:
  virtual ~HandInput() = default;
  /// The hand for step `step` at simulation time `time` (s).
  virtual HandFrame frame(std::uint64_t step, double time) = 0;
  /// True once the source has nothing more to give (a script past its end, a recording's last step).
  virtual bool finished(std::uint64_t step, double time) const = 0;
};

}  // namespace vrd
