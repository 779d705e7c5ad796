#include "vrdeform/interact/hand_rig.h"

#include "vrdeform/error.h"

namespace vrd {

HandRig::HandRig(World& world, const HandRigSettings& settings, const HandFrame& initial) : settings_(settings) {
  if (!(settings.geometry.fingertipRadius > 0.0f && std::isfinite(settings.geometry.fingertipRadius)))
    throw Error("hand: fingertip radius must be positive");
  targets_ = targetsFor(initial);
  for (int f = 0; f < kFingerCount; ++f) {
    if (!settings.fingers[f]) continue;
    if (!isFinite(targets_[f])) throw Error("hand: the initial frame puts a fingertip at a non-finite position");
    tips_[f] =
        world.addFingertip(targets_[f], settings.geometry.fingertipRadius, settings.compliance, settings.contact);
    world.setFingertipFriction(*tips_[f], settings.friction);
  }
  if (!initial.direct) wrist_ = initial.pose.wrist;
}

std::array<Vec3, kFingerCount> HandRig::targetsFor(const HandFrame& frame) const {
  if (frame.direct) return frame.fingertips;
  std::array<Vec3, kFingerCount> out;
  for (int f = 0; f < kFingerCount; ++f) out[f] = fingertipPosition(settings_.geometry, frame.pose, Finger(f));
  return out;
}

void HandRig::apply(World& world, const HandFrame& frame) {
  const std::array<Vec3, kFingerCount> next = targetsFor(frame);
  for (int f = 0; f < kFingerCount; ++f) {
    if (!tips_[f] || !isFinite(next[f])) continue;
    targets_[f] = next[f];
    world.moveFingertip(*tips_[f], next[f]);
  }
  if (!frame.direct && frame.pose.wrist.matrix().allFinite()) wrist_ = frame.pose.wrist;
}

Vec3 HandRig::meanFingertip() const {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (int f = 0; f < kFingerCount; ++f)
    if (tips_[f]) sum += targets_[f], ++n;
  return n > 0 ? Vec3(sum / float(n)) : sum;
}

}  // namespace vrd
