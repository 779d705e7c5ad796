#pragma once
// The VR viewer's hand: what a WebXR page reports of the user's controller or tracked hand, and
// how it becomes the simulation's hand (docs/vr.md#hand-input). A controller is a pinch: the
// thumb and the index face each other across a point just ahead of the controller, and the
// trigger closes the gap; a tracked hand's fingertips are the fingertip centres themselves.
//
// Everything is in scene coordinates (metres, y up): the page converts from its XR space.

#include <array>
#include <cstdint>
#include <optional>

#include "vrdeform/interact/hand.h"

namespace vrd {

struct XrPose {
  Vec3 position = Vec3::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();  ///< unit
};

enum class XrSource : std::uint8_t {
  None,        ///< nothing tracked: the hand waits parked
  Controller,  ///< a tracked controller: its target ray and trigger
  Hand,        ///< a tracked hand: its fingertip joints
};

/// One input message of a viewer (docs/vr.md#client-messages).
struct XrInput {
  XrSource source = XrSource::None;
  /// Controller: its target ray. -z points ahead of the controller, +y is the controller's up.
  XrPose ray;
  float trigger = 0.0f;  ///< controller: [0, 1]
  float squeeze = 0.0f;  ///< controller: [0, 1] (reported; not used by the mapping)
  /// Hand: fingertip joint positions, thumb to little; NaN where the joint is not tracked.
  std::array<Vec3, kFingerCount> tips{Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  std::optional<XrPose> head;  ///< the headset, when reported
};

struct XrHandSettings {
  float reach = 0.03f;       ///< from the ray's origin ahead to the middle of the pinch (m)
  float openGap = 0.06f;     ///< gap between the thumb's and the index's surfaces, trigger released (m)
  float closedGap = 0.0f;    ///< the same gap with the trigger pressed fully (m)
  double timeout = 0.5;      ///< s without input before the hand goes back to its park (the server's)
  Vec3 park = Vec3::Zero();  ///< the middle of the pinch while no viewer drives the hand
};

/// The fingertip centres for one input: a controller's pinch (index above the thumb along the
/// ray's +y; middle, ring and little trailing the index back along the ray, 2.2 radii apart) with
/// the gap from `closure` when given (a glove), else from the trigger; a hand's tips as they are.
/// A source of None gives the parked hand.
HandFrame xrHandFrame(const XrInput& input, const XrHandSettings& settings, float fingertipRadius,
                      std::optional<float> closure = {});

/// The hand waiting at settings.park, open, the controller pointing down.
HandFrame xrParkedFrame(const XrHandSettings& settings, float fingertipRadius);

}  // namespace vrd
