#pragma once
// A kinematic hand that turns a wrist pose and one closure value per finger (what a glove such as
// the TouchDIVER reports) into fingertip positions. Each finger is a planar chain of three
// phalanges from its knuckle; closure c in [0, 1] bends its three joints by c times their range.
//
// Wrist frame (right hand, metres): +x from the wrist towards the fingertips, +y towards the thumb
// side, +z out of the palm. Fingers curl towards +z; the thumb curls across the palm towards -y.

#include <array>
#include <string_view>

#include "vrdeform/math/types.h"

namespace vrd {

enum class Finger { Thumb, Index, Middle, Ring, Little };
inline constexpr int kFingerCount = 5;

/// "thumb", "index", "middle", "ring", "little": the names in file headers, messages and docs.
constexpr std::string_view fingerName(Finger finger) {
  constexpr std::array<std::string_view, kFingerCount> kNames{"thumb", "index", "middle", "ring", "little"};
  const int i = static_cast<int>(finger);
  return i >= 0 && i < kFingerCount ? kNames[std::size_t(i)] : std::string_view("finger?");
}

struct FingerGeometry {
  Vec3 knuckle;                   ///< base joint in the wrist frame
  Vec3 direction;                 ///< unit direction of the straight finger
  Vec3 bendAxis;                  ///< unit axis the joints turn about (right-hand rule)
  std::array<float, 3> phalanx;   ///< proximal, middle, distal lengths
  std::array<float, 3> maxAngle;  ///< joint ranges (radians) at closure 1
};

/// An adult hand of average size (hand length ~19 cm), with joint ranges of about 90/100/70
/// degrees for the fingers and 50/60/70 for the thumb.
struct HandGeometry {
  std::array<FingerGeometry, kFingerCount> fingers;
  float fingertipRadius = 0.009f;
  static HandGeometry average();
};

struct HandPose {
  Eigen::Isometry3f wrist = Eigen::Isometry3f::Identity();
  std::array<float, kFingerCount> closure{};  ///< 0 open .. 1 closed; clamped, NaN reads as open
};

/// One step of hand input: a wrist pose with finger closures (gloves, scripts), or fingertip
/// centres given directly (tracked hands, controllers, mouse).
struct HandFrame {
  HandPose pose;
  bool direct = false;  ///< use `fingertips` as they are instead of the pose
  /// World fingertip centres when direct (Eigen leaves a default Vec3 uninitialised, hence the zeros).
  std::array<Vec3, kFingerCount> fingertips{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
};

/// The centre of a fingertip sphere in world coordinates.
Vec3 fingertipPosition(const HandGeometry& hand, const HandPose& pose, Finger finger);

}  // namespace vrd
