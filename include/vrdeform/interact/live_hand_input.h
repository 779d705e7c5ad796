#pragma once
// A hand set from another thread, e.g. a viewer's mouse or a VR controller, and read by the
// simulation loop: the newest frame set wins. Both sides are wait-free (a triple buffer), so a
// busy user interface never stalls the loop, nor the loop the interface.

#include <array>
#include <atomic>
#include <cstdint>

#include "vrdeform/interact/hand_input.h"

namespace vrd {

class LiveHandInput final : public HandInput {
 public:
  explicit LiveHandInput(const HandFrame& initial = {});

  /// Writer (one thread): makes `frame` the hand from the reader's next frame() on.
  void set(const HandFrame& frame);

  /// Reader (one thread): the newest frame set, or the one before if none arrived since.
  HandFrame frame(std::uint64_t step, double time) override;
  bool finished(std::uint64_t, double) const override { return false; }  ///< a live hand never ends

 private:
  static constexpr unsigned kIndex = 3, kFresh = 4;
  std::array<HandFrame, 3> slots_;
  alignas(64) std::atomic<unsigned> middle_{1};
  alignas(64) unsigned back_ = 2;   // the writer's
  alignas(64) unsigned front_ = 0;  // the reader's
};

}  // namespace vrd
