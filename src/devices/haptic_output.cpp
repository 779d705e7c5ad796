#include "vrdeform/devices/haptic_output.h"

namespace vrd {

HapticSample sanitised(const HapticSample& sample) {
  HapticSample out;
  out.time = std::isfinite(sample.time) ? sample.time : 0.0;
  out.paper = clampUnit(sample.paper);
  out.present = sample.present;
  for (int f = 0; f < kFingerCount; ++f) {
    if (!sample.present[f]) continue;
    out.force[f] = clampUnit(sample.force[f]);
    out.newtons[f] = clampNewtons(sample.newtons[f]);
  }
  return out;
}

HapticSample sampleOf(double time, const HapticFrame& frame, const std::array<bool, kFingerCount>& present) {
  HapticSample sample;
  sample.time = time;
  sample.paper = frame.paper;
  sample.present = present;
  for (int f = 0; f < kFingerCount; ++f) {
    sample.force[f] = frame.fingers[f].force;
    sample.newtons[f] = frame.fingers[f].newtons;
  }
  return sanitised(sample);
}

}  // namespace vrd
