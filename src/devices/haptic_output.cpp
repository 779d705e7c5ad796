#include "vrdeform/devices/haptic_output.h"

#include "vrdeform/haptics/haptic_session.h"

namespace vrd {
namespace {

float finiteOrZero(float v) { return std::isfinite(v) ? v : 0.0f; }

}  // namespace

HapticSample sanitised(const HapticSample& sample) {
  HapticSample out;
  out.step = sample.step;
  out.time = std::isfinite(sample.time) ? sample.time : 0.0;
  out.paper = clampUnit(sample.paper);
  out.paperRaw = clampUnit(sample.paperRaw);
  out.grasp = sample.grasp;
  out.present = sample.present;
  for (int f = 0; f < kFingerCount; ++f) {
    if (!sample.present[f]) continue;
    out.force[f] = clampUnit(sample.force[f]);
    out.newtons[f] = clampNewtons(sample.newtons[f]);
    out.raw[f] = clampUnit(sample.raw[f]);
    out.baseline[f] = clampUnit(sample.baseline[f]);
    out.depth[f] = clampNewtons(sample.depth[f]);  // a length, by the same rule: finite and >= 0
    out.contacts[f] = sample.contacts[f];
    out.tip[f] = sample.tip[f].unaryExpr([](float v) { return finiteOrZero(v); });
  }
  return out;
}

HapticSample sampleOf(std::uint64_t step, double dt, const HapticFrame& frame,
                      const std::array<bool, kFingerCount>& present) {
  HapticSample sample;
  sample.step = step;
  sample.time = double(step) * dt;
  sample.paper = frame.paper;
  sample.paperRaw = frame.paperRaw;
  sample.present = present;
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerHaptics& finger = frame.fingers[f];
    sample.force[f] = finger.force;
    sample.newtons[f] = finger.newtons;
    sample.raw[f] = finger.raw;
    sample.baseline[f] = finger.baseline;
    sample.depth[f] = finger.depth;
    sample.contacts[f] = std::uint32_t(finger.contacts);
  }
  return sanitised(sample);
}

HapticSample sampleOf(std::uint64_t step, const HapticSession& session) {
  const HandRig& rig = session.rig();
  HapticSample sample = sampleOf(step, session.world().settings().timeStep, session.haptics(), rig.settings().fingers);
  sample.grasp = session.grasp().active();
  for (int f = 0; f < kFingerCount; ++f)
    if (sample.present[f] && rig.has(Finger(f)))  // the rest is sanitised already: only the tips are new
      sample.tip[f] =
          session.world().fingertip(rig.fingertip(Finger(f))).center.unaryExpr([](float v) { return finiteOrZero(v); });
  return sample;
}

}  // namespace vrd
