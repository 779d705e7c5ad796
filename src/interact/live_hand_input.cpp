#include "vrdeform/interact/live_hand_input.h"

namespace vrd {

LiveHandInput::LiveHandInput(const HandFrame& initial) { slots_.fill(initial); }

// As SnapshotChannel: acq_rel exchanges hand each slot's contents to the side that takes it next.
void LiveHandInput::set(const HandFrame& frame) {
  slots_[back_] = frame;
  back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex;
}

HandFrame LiveHandInput::frame(std::uint64_t, double) {
  if (middle_.load(std::memory_order_relaxed) & kFresh)
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
  return slots_[front_];
}

}  // namespace vrd
