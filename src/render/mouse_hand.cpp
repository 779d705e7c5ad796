#include "vrdeform/render/mouse_hand.h"

#include <algorithm>
#include <cmath>

namespace vrd {
namespace {

// Where the ray meets the plane through `point` facing the camera.
Vec3 onViewPlane(const Ray& ray, const Vec3& point, const Vec3& forward) {
  const float along = (point - ray.origin).dot(forward) / std::max(ray.direction.dot(forward), 1e-6f);
  return ray.origin + along * ray.direction;
}

}  // namespace

MouseHand::MouseHand(float radius, const Vec3& park) : radius_(radius), park_(park) {}

HandFrame MouseHand::parked() const {
  HandFrame f;
  f.direct = true;
  for (int i = 0; i < kFingerCount; ++i) f.fingertips[i] = park_ + Vec3(0.05f * float(i), 0.0f, 0.0f);
  return f;
}

HandFrame MouseHand::update(const MouseState& mouse, const PosedScene& scene, const OrbitCamera& camera, float dt) {
  const Ray ray = camera.ray(mouse.x, mouse.y, mouse.width, mouse.height);
  const Vec3 forward = camera.forward();
  HandFrame frame = parked();
  const int thumb = int(Finger::Thumb), index = int(Finger::Index);

  if (mode_ == Mode::Idle) {
    if (mouse.poke || mouse.pinch) {
      if (const std::optional<RayHit> hit = scene.pick(ray)) {
        if (mouse.poke) {
          mode_ = Mode::Poke;
          held_ = 0.0f;
          hitDepth_ = hit->distance;
        } else {
          // Across the body along the screen's horizontal, through a point just under the surface.
          axis_ = camera.right();
          const Vec3 inside = hit->point + 0.5f * radius_ * ray.direction;
          const float reach = std::max(scene.bounds().diagonal().norm(), 10.0f * radius_);
          const std::optional<RayHit> plus = scene.pick({inside + reach * axis_, -axis_});
          const std::optional<RayHit> minus = scene.pick({inside - reach * axis_, axis_});
          const Vec3 a = minus ? minus->point : Vec3(inside - radius_ * axis_);
          const Vec3 b = plus ? plus->point : Vec3(inside + radius_ * axis_);
          centre_ = 0.5f * (a + b);
          const float width = (b - a).dot(axis_);
          open_ = width + 2.0f * radius_ + 0.02f;  // 1 cm clear of each side
          closed_ = std::max(width + 2.0f * radius_ * (1.0f - settings.pinchDepth), radius_);
          aperture_ = open_;
          grabbed_ = onViewPlane(ray, centre_, forward);
          shift_ = Vec3::Zero();
          mode_ = Mode::Pinch;
        }
      }
    }
  } else if (mode_ == Mode::Poke && !mouse.poke) {
    mode_ = Mode::Idle;
  } else if (mode_ == Mode::Pinch && !mouse.pinch) {
    mode_ = Mode::Opening;
  }

  active_.fill(false);
  if (mode_ == Mode::Poke) {
    held_ += dt;
    const float depth = settings.pokeDepth * radius_ * std::min(held_ / std::max(settings.pressSeconds, 1e-3f), 1.0f);
    frame.fingertips[index] = ray.origin + (hitDepth_ - radius_ + depth) * ray.direction;
    active_[index] = true;
  } else if (mode_ == Mode::Pinch || mode_ == Mode::Opening) {
    if (mode_ == Mode::Pinch) {
      aperture_ = std::max(aperture_ - settings.closingSpeed * dt, closed_);
      shift_ = onViewPlane(ray, grabbed_, forward) - grabbed_;
    } else {
      aperture_ += settings.closingSpeed * dt;
      // 2 cm wider than the pinch began: a grasp began at that aperture or inside it, and 2 cm outdo
      // its 1 cm hysteresis, so it always lets go before the fingers park.
      if (aperture_ >= open_ + 0.02f) mode_ = Mode::Idle;
    }
    const Vec3 c = centre_ + shift_;
    frame.fingertips[thumb] = c - 0.5f * aperture_ * axis_;
    frame.fingertips[index] = c + 0.5f * aperture_ * axis_;
    active_[thumb] = active_[index] = mode_ != Mode::Idle;
  }
  return frame;
}

}  // namespace vrd
