#include "vrdeform/scene/snapshot.h"

namespace vrd {

SnapshotChannel::SnapshotChannel(std::size_t particles, std::size_t bodies) {
  for (Snapshot& s : slots_) {
    s.positions.reserve(particles);
    s.bodyFirst.reserve(bodies);
  }
}

// acq_rel on both exchanges: the release publishes the slot's contents to the side that takes it
// next; the acquire makes the contents written by the side that gave the slot up visible here
// before this side overwrites (writer) or reads (reader) it.
void SnapshotChannel::publish() { back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex; }

bool SnapshotChannel::update() {
  if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
  // Only the writer changes middle_ meanwhile, and it always leaves it fresh: this takes a new slot.
  front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
  return true;
}

bool SnapshotChannel::read(Snapshot& out) {
  if (!update()) return false;
  out = front();
  return true;
}

}  // namespace vrd
