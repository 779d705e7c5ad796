#include "vrdeform/study/trial_events.h"

#include <fmt/format.h>

namespace vrd {

void TrialEvents::send(const HapticSample& sample) {
  for (int f = 0; f < kFingerCount; ++f) {
    const bool touching = sample.present[f] && sample.contacts[f] > 0;
    if (touching != touching_[f]) events_.push_back({sample.step, sample.time, touching ? "touch" : "untouch", f});
    touching_[f] = touching;
  }
  if (sample.grasp != grasping_) events_.push_back({sample.step, sample.time, sample.grasp ? "grasp" : "ungrasp", -1});
  grasping_ = sample.grasp;
}

std::string TrialEvents::csv() const {
  std::string out = "step,time_s,event,finger\n";
  for (const Event& e : events_)
    out += fmt::format("{},{},{},{}\n", e.step, e.time, e.what, e.finger < 0 ? "" : fingerName(Finger(e.finger)));
  return out;
}

}  // namespace vrd
