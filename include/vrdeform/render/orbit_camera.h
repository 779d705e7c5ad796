#pragma once
// A camera that orbits a target point: yaw about the vertical (+y), pitch above the horizon and a
// distance. Gives the view and projection matrices, and the ray through a pixel for picking.

#include <optional>

#include "vrdeform/math/types.h"

namespace vrd {

struct Ray {
  Vec3 origin = Vec3::Zero();
  Vec3 direction = Vec3::UnitZ();  ///< unit
};

struct OrbitCamera {
  Vec3 target = Vec3::Zero();
  float yaw = 0.6f;       ///< radians about +y; 0 looks along -z
  float pitch = 0.45f;    ///< radians above the horizon (looking down for > 0), kept within +-1.5
  float distance = 1.0f;  ///< from the target (m)
  float fovY = 0.7f;      ///< vertical field of view (radians)

  Vec3 eye() const;
  Vec3 forward() const;  ///< unit, from the eye towards the target
  Vec3 right() const;    ///< unit, horizontal
  Vec3 up() const;       ///< unit, completes the frame
  Eigen::Matrix4f view() const;
  /// Perspective with near and far planes scaled to the distance.
  Eigen::Matrix4f projection(float aspect) const;

  /// Aims at the box's centre from far enough that its bounding sphere fills about `fill` of the
  /// view's height.
  void frame(const Eigen::AlignedBox3f& box, float fill = 0.7f);
  void orbit(float dYaw, float dPitch);
  void zoom(float factor);  ///< distance *= factor
  /// Moves the target within the view plane by a fraction of the visible height.
  void pan(float dx, float dy);

  /// The ray from the eye through pixel (x, y) of a width x height image (y down).
  Ray ray(float x, float y, int width, int height) const;
  /// Where a point lands on a width x height image (pixels, y down); nothing behind the eye.
  std::optional<Eigen::Vector2f> project(const Vec3& point, int width, int height) const;
};

}  // namespace vrd
