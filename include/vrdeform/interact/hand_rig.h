#pragma once
// A hand in a world: one fingertip sphere per actuated finger, moved each step from a HandFrame.
// The TouchDIVER G1 actuates thumb, index and middle; the Pro adds ring and little.

#include <array>
#include <optional>

#include "vrdeform/interact/hand.h"
#include "vrdeform/sim/world.h"

namespace vrd {

struct HandRigSettings {
  HandGeometry geometry = HandGeometry::average();                         ///< kinematic hand for pose-driven frames
  std::array<bool, kFingerCount> fingers{true, true, true, false, false};  ///< fingers with a fingertip (G1)
  float compliance = 0.0f;  ///< alpha of the fingertip contacts (m/N); 0 = rigid fingertips
  /// Particles: the paper's contacts (eqs. 36-39). Triangles: against the bodies' surface
  /// triangles, so a fingertip pressing between the vertices of a coarse mesh still touches.
  FingertipContactMode contact = FingertipContactMode::Particles;
  FingertipFriction friction;  ///< of the fingertips' contacts (none: the paper's)

  static HandRigSettings g1() { return {}; }
  static HandRigSettings pro() {
    HandRigSettings s;
    s.fingers.fill(true);
    return s;
  }
};

class HandRig {
 public:
  /// Adds the fingertips to `world`, placed where `initial` puts them.
  HandRig(World& world, const HandRigSettings& settings, const HandFrame& initial = {});

  /// Sends the fingertips to where `frame` puts them by the end of the next step. A non-finite
  /// fingertip or wrist (a broken tracker) keeps that fingertip where it was.
  void apply(World& world, const HandFrame& frame);

  const HandRigSettings& settings() const { return settings_; }
  bool has(Finger f) const { return tips_[int(f)].has_value(); }
  FingertipId fingertip(Finger f) const { return tips_[int(f)].value(); }
  /// Where the finger's fingertip centre is going in this step (its goal).
  const Vec3& target(Finger f) const { return targets_[int(f)]; }
  /// The last valid wrist pose (identity for direct frames); rotates local-grasp holds.
  const Eigen::Isometry3f& wrist() const { return wrist_; }
  /// Mean of the fingertip targets: the paper's grasp centre p_g (Algorithm 2, line 24).
  Vec3 meanFingertip() const;

 private:
  std::array<Vec3, kFingerCount> targetsFor(const HandFrame& frame) const;

  HandRigSettings settings_;
  std::array<std::optional<FingertipId>, kFingerCount> tips_;
  std::array<Vec3, kFingerCount> targets_{};
  Eigen::Isometry3f wrist_ = Eigen::Isometry3f::Identity();
};

}  // namespace vrd
