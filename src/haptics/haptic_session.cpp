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
  return haptics_.frame();
}

}  // namespace vrd
