#include "vrdeform/scene/snapshot.h"

#include "vrdeform/haptics/haptic_session.h"

namespace vrd {

void captureSnapshot(Snapshot& s, const World& world, const HapticSession* session, std::uint64_t step, double time,
                     double stepWallMs) {
  s.step = step;
  s.time = time;
  const std::vector<Point>& x = world.particles().x;
  s.positions.resize(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) s.positions[i] = x[i].pos;
  s.bodyFirst.resize(world.bodyCount());
  for (std::size_t b = 0; b < s.bodyFirst.size(); ++b) s.bodyFirst[b] = world.body(BodyId(b)).firstParticle;
  s.constraintForce.clear();
  s.fingerPresent = {};
  s.fingertips.fill(Vec3::Zero());
  s.fingertipRadius = 0.0f;
  s.haptics = {};
  s.grasping = false;
  s.contact = false;
  if (session) {
    const HandRig& rig = session->rig();
    for (int f = 0; f < kFingerCount; ++f)
      if (rig.has(Finger(f))) {
        const Fingertip& tip = world.fingertip(rig.fingertip(Finger(f)));
        s.fingerPresent[f] = true;
        s.fingertips[f] = tip.center;
        s.fingertipRadius = tip.radius;
      }
    s.haptics = session->haptics();
    s.grasping = session->grasp().active();
    s.contact = session->inContact();
  }
  s.times = session ? session->times() : world.lastStep().times;
  s.residuals = world.lastStep().residuals;
  s.iterations = world.lastStep().iterations;
  s.stepWallMs = stepWallMs;
}

void captureConstraintForces(Snapshot& s, const World& world) {
  s.constraintForce.assign(world.particles().x.size(), 0.0f);
  for (std::size_t b = 0; b < world.bodyCount(); ++b) {
    const std::vector<Vec3> f = world.particleMaterialForces(BodyId(b));
    const std::uint32_t first = world.body(BodyId(b)).firstParticle;
    for (std::size_t i = 0; i < f.size(); ++i) s.constraintForce[first + i] = f[i].norm();
  }
}

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
