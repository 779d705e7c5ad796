#include "vrdeform/haptics/haptic_session.h"

namespace vrd {

HapticSession::HapticSession(World& world, const HapticSessionSettings& settings, const HandFrame& initial)
    : world_(world), rig_(world, settings.hand, initial), grasp_(settings.grasp), haptics_(settings.haptics) {}

const HapticFrame& HapticSession::step(const HandFrame& input) {
  const bool timed = world_.settings().timeStages;
  StageTimes own;
  {
    StageTimer t(own, Stage::Interact, timed);
    rig_.apply(world_, input);
    grasp_.update(world_, rig_);
  }
  world_.step();
  {
    StageTimer t(own, Stage::Force, timed);
    haptics_.update(world_, rig_, grasp_);
  }
  times_ = world_.lastStep().times;
  times_[Stage::Interact] = own[Stage::Interact];
  times_[Stage::Force] = own[Stage::Force];
  ++steps_;
  return haptics_.frame();
}

std::uint64_t HapticSession::run(HandInput& input, std::uint64_t maxSteps,
                                 const std::function<void(const RecordedStep&)>& record) {
  std::uint64_t done = 0;
  for (; done < maxSteps; ++done) {
    const double time = double(steps_) * world_.settings().timeStep;
    if (input.finished(steps_, time)) break;
    const HandFrame frame = input.frame(steps_, time);
    step(frame);
    if (record) record({frame, recordedOutputs(haptics())});
  }
  return done;
}

bool HapticSession::inContact() const {
  if (grasp_.active()) return true;
  for (const FingerHaptics& f : haptics().fingers)
    if (f.contacts > 0) return true;
  return false;
}

std::vector<float> recordedOutputs(const HapticFrame& frame) {
  std::vector<float> out{frame.paper, frame.paperRaw};
  for (const FingerHaptics& f : frame.fingers) out.insert(out.end(), {f.force, f.raw, f.newtons, f.baseline});
  return out;
}

}  // namespace vrd
