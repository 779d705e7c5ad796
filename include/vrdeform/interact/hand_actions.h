#pragma once
// Scripted pokes and pinch grasps aimed at points of a body, as fingertip centres given directly
// (HandFrame::direct). Scenes aim each at a body's top as the action starts (scene/scene_spec.h);
// the `touch` command's standard poke is one of them.

#include <functional>
#include <vector>

#include "vrdeform/interact/hand_input.h"

namespace vrd {

enum class ActionKind { Poke, Grasp };

/// How a poke moves between its depths: along a minimum-jerk profile, starting and stopping
/// smoothly as a reaching hand does, or at a constant speed (an indentation test's ramp).
enum class PokeProfile { MinimumJerk, Linear };

/// One action in world coordinates, timed in simulation seconds. Depths are of a fingertip's lowest
/// point below `target`; at rest an acting fingertip waits with its lowest point one radius above.
struct HandAction {
  ActionKind kind = ActionKind::Poke;
  Finger finger = Finger::Index;  ///< the poking finger, or the one pinching against the thumb
  Vec3 target = Vec3::Zero();     ///< the point poked, or the middle of the pinch (on the body's top)
  double start = 0.0;             ///< s
  /// Poke: down to `depth` in `approach`, stay `hold`, back up in `release`, each move along
  /// `profile`. Grasp: down to `depth` in
  /// the first 40% of `approach`, then close the gap in the rest; lift by `lift` in the first third
  /// of `hold`; lower by half the lift, open (2 cm wider than at the start, so the grasp lets go)
  /// and rise in three equal parts of `release`, letting the body drop the rest.
  double approach = 1.0, hold = 1.0, release = 1.0;
  float depth = 0.01f;  ///< m
  float width = 0.0f;   ///< grasp: gap between the fingertips' surfaces before closing (m); 0: 4 radii
  float lift = 0.0f;    ///< grasp: m
  PokeProfile profile = PokeProfile::MinimumJerk;  ///< poke

  double end() const { return start + approach + hold + release; }
};

/// Plays actions one after another (they may not overlap: vrd::Error). Fingertips not acting wait
/// 1 m above the current (or next, or last) target, spaced 5 cm apart.
class HandActionsInput final : public HandInput {
 public:
  /// Where action `index` (of those given) aims, asked once as it starts: a body poked may have
  /// moved since the actions were planned. Its answer replaces the target unless it is not finite.
  using Aim = std::function<Vec3(std::size_t index)>;

  /// Throws vrd::Error for non-finite or negative values, overlapping actions or a grasp by the thumb.
  HandActionsInput(std::vector<HandAction> actions, float fingertipRadius, Aim aim = {});

  HandFrame frame(std::uint64_t step, double time) override;
  /// After the last action has ended (or for a NaN time).
  bool finished(std::uint64_t step, double time) const override;
  const std::vector<HandAction>& actions() const { return actions_; }

 private:
  std::vector<HandAction> actions_;  // sorted by start
  std::vector<std::size_t> given_;   // each one's index among those given
  std::vector<bool> aimed_;
  std::size_t next_ = 0;  // the first action not ended at the last frame's time
  float radius_;
  Aim aim_;
};

}  // namespace vrd
