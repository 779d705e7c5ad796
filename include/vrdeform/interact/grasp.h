#pragma once
// Grasping a body between the thumb and another finger (paper eq. 35, Algorithm 2 lines 3-10).
//
// A pinch starts when the thumb and another fingertip both touch the same body in the last step
// while the gap between them (the aperture) is closing. It ends, with hysteresis, once the
// aperture has opened `releaseOpening` beyond its value at the start, so a grasp does not flicker
// on and off while the user squeezes.

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "vrdeform/interact/hand_rig.h"

namespace vrd {

enum class GraspMode : std::uint8_t {
  Paper,  ///< eq. 35: every particle of the body follows the hand's displacement from its cached position
  Local,  ///< only particles within the pinch hang on the pinching fingertips, by compliant attachments
};

struct GraspSettings {
  GraspMode mode = GraspMode::Local;
  bool enabled = true;
  float releaseOpening = 0.01f;  ///< hysteresis: aperture growth that ends a grasp (m)
  float closingSpeed = 0.0f;     ///< a pinch starts only while the aperture shrinks faster than this (m/s)
  float holdReach = 1.5f;        ///< local: particles within holdReach x fingertip radius of a pinching tip are held
  float holdCompliance = 1e-5f;  ///< local: alpha of each hold (m/N)
};

/// Throws vrd::Error for negative or non-finite values.
void validateGraspSettings(const GraspSettings& settings);

class Grasp {
 public:
  explicit Grasp(const GraspSettings& settings = {});

  /// Call once per step after HandRig::apply and before World::step: starts or ends the grasp from
  /// the last step's contacts and the new fingertip targets, and moves the grasped particles.
  void update(World& world, const HandRig& rig);
  /// Ends the grasp now: the body keeps its velocity and falls; the fingertips touch again.
  void release(World& world, const HandRig& rig);

  const GraspSettings& settings() const { return settings_; }
  bool active() const { return active_; }
  BodyId body() const { return body_; }
  bool pinching(Finger f) const { return active_ && pinching_[int(f)]; }
  /// Local mode: the force the finger's holds apply to the body (N); zero in paper mode, where the
  /// body is prescribed and no force is computed.
  Vec3 holdForce(const World& world, Finger f) const;
  std::size_t heldParticles() const { return holds_.size(); }

 private:
  struct Hold {
    AttachmentId attachment;
    Finger finger;
    Vec3 offset;  ///< from the fingertip centre to the particle, in the wrist frame at the start
  };

  void begin(World& world, const HandRig& rig, BodyId body, const std::array<bool, kFingerCount>& pinching);
  void follow(World& world, const HandRig& rig);
  Vec3 pinchCentre(const HandRig& rig) const;

  GraspSettings settings_;
  bool active_ = false;
  BodyId body_ = 0;
  std::array<bool, kFingerCount> pinching_{};
  Finger partner_ = Finger::Index;  ///< the finger whose gap to the thumb decides the release
  float startAperture_ = 0.0f;
  /// Thumb-to-finger gaps of the previous update; NaN (none yet) compares false, so nothing closes.
  std::array<float, kFingerCount> lastAperture_ = noApertures();
  static std::array<float, kFingerCount> noApertures() {
    std::array<float, kFingerCount> a;
    a.fill(std::numeric_limits<float>::quiet_NaN());
    return a;
  }

  // Paper mode: x_ref (eq. 35) and the hand displacement so far.
  std::vector<Vec3> reference_;
  Vec3 anchor_ = Vec3::Zero();
  Vec3 lastShift_ = Vec3::Zero();
  // Local mode.
  std::vector<Hold> holds_;
  Eigen::Quaternionf startWrist_ = Eigen::Quaternionf::Identity();
};

}  // namespace vrd
