#pragma once
// One user's hand on a world, stepped as Algorithm 2: hand input -> grasp -> XPBD step -> haptic
// force. Single-threaded and deterministic: the same world and inputs give the same bits.

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/grasp.h"
#include "vrdeform/interact/hand_rig.h"

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

  World& world() { return world_; }
  const World& world() const { return world_; }
  const HandRig& rig() const { return rig_; }
  const Grasp& grasp() const { return grasp_; }
  const HapticFrame& haptics() const { return haptics_.frame(); }
  /// The last step's stage times: the world's, plus Interact and Force.
  const StageTimes& times() const { return times_; }

 private:
  World& world_;
  HandRig rig_;
  Grasp grasp_;
  HapticModel haptics_;
  StageTimes times_;
};

}  // namespace vrd
