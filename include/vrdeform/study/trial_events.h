#pragma once
// A study trial's task events (docs/study.md): when each finger began and ended touching a body
// and when each grasp began and ended, at the step they happened. An output of the trial's run or
// loop, so that it sees every step; the trial writes them as events.csv.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vrdeform/devices/haptic_output.h"

namespace vrd {

class TrialEvents final : public HapticOutput {
 public:
  TrialEvents() { events_.reserve(256); }
  void send(const HapticSample& sample) override;
  void release() override {}
  /// `step,time_s,event,finger`: event touch, untouch (finger named), grasp, ungrasp (finger empty).
  std::string csv() const;
  std::size_t size() const { return events_.size(); }

 private:
  struct Event {
    std::uint64_t step;
    double time;
    const char* what;
    int finger;  // -1: the hand
  };
  std::vector<Event> events_;
  std::array<bool, kFingerCount> touching_{};
  bool grasping_ = false;
};

}  // namespace vrd
