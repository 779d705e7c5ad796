#pragma once
// One user's hand on a world, stepped as Algorithm 2: hand input -> grasp -> XPBD step -> haptic
// force. Single-threaded and deterministic: the same world and inputs give the same bits.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/grasp.h"
#include "vrdeform/interact/hand_input.h"
#include "vrdeform/interact/hand_rig.h"
#include "vrdeform/interact/session_recording.h"

namespace vrd {

struct HapticSessionSettings {
  HandRigSettings hand;
  GraspSettings grasp;
  HapticSettings haptics;
};

class HapticSession {
 public:
  /// Adds the hand's fingertips to `world`, which must outlive the session.
  HapticSession(World& world, const HapticSessionSettings& settings, const HandFrame& initial = {});

  /// One step: moves the hand to `input`, starts/ends/follows a grasp, steps the world and
  /// computes the haptic outputs.
  const HapticFrame& step(const HandFrame& input);
  /// Steps through `input` (step k at time k dt from this session's first step) until it is
  /// finished or `maxSteps` have run; hands each step to `record` when given (to keep in a
  /// SessionRecording, or to write with a SessionRecordingWriter). Returns the steps run.
  std::uint64_t run(HandInput& input, std::uint64_t maxSteps,
                    const std::function<void(const RecordedStep&)>& record = {});

  World& world() { return world_; }
  const World& world() const { return world_; }
  const HandRig& rig() const { return rig_; }
  const Grasp& grasp() const { return grasp_; }
  /// A finger touched a body in the last step, or a grasp holds one: the paper's "contact" state
  /// (Table 3), as opposed to idle.
  bool inContact() const;
  const HapticFrame& haptics() const { return haptics_.frame(); }
  /// The last step's stage times: the world's, plus Interact and Force.
  const StageTimes& times() const { return times_; }

 private:
  World& world_;
  HandRig rig_;
  Grasp grasp_;
  HapticModel haptics_;
  StageTimes times_;
  std::uint64_t steps_ = 0;
};

/// The values a recording keeps per step, in this order: paper, paperRaw, then per finger force,
/// raw, newtons, baseline.
std::vector<float> recordedOutputs(const HapticFrame& frame);
/// What output j of recordedOutputs is: "paper", "paper raw", "index newtons", ...
std::string recordedOutputName(std::size_t j);
/// A replay's check of step `step`: "" when its outputs equal the recorded ones bit for bit, else
/// "differs at step K (output J: RECORDED vs REPLAYED)" with both in hexadecimal and in decimal.
std::string replayDifference(std::uint64_t step, const std::vector<float>& recorded,
                             const std::vector<float>& replayed);

}  // namespace vrd
