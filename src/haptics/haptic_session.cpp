#include "vrdeform/haptics/haptic_session.h"

#include <fmt/format.h>

#include <array>
#include <cstring>

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

std::string recordedOutputName(std::size_t j) {
  if (j == 0) return "paper";
  if (j == 1) return "paper raw";
  constexpr std::array<const char*, 4> kinds{"force", "raw", "newtons", "baseline"};
  if (j - 2 < std::size_t(4 * kFingerCount))
    return fmt::format("{} {}", fingerName(Finger((j - 2) / 4)), kinds[(j - 2) % 4]);
  return fmt::format("output {}", j);
}

std::string replayDifference(std::uint64_t step, const std::vector<float>& recorded,
                             const std::vector<float>& replayed) {
  if (recorded.size() != replayed.size())
    return fmt::format("differs at step {} (output count: {} vs {})", step, recorded.size(), replayed.size());
  for (std::size_t j = 0; j < recorded.size(); ++j)
    if (std::memcmp(&recorded[j], &replayed[j], sizeof(float)) != 0)
      return fmt::format(
          "differs at step {} (output {}: {:a} vs {:a})\n  output {} is {}; recorded value first, replayed second "
          "({:.9g} vs {:.9g})",
          step, j, double(recorded[j]), double(replayed[j]), j, recordedOutputName(j), recorded[j], replayed[j]);
  return "";
}

}  // namespace vrd
