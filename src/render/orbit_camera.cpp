#include "vrdeform/render/orbit_camera.h"

#include <algorithm>
#include <cmath>

namespace vrd {

Vec3 OrbitCamera::forward() const {
  const float c = std::cos(pitch);
  return Vec3(-c * std::sin(yaw), -std::sin(pitch), -c * std::cos(yaw));
}

Vec3 OrbitCamera::eye() const { return target - distance * forward(); }
Vec3 OrbitCamera::right() const { return Vec3(std::cos(yaw), 0.0f, -std::sin(yaw)); }
Vec3 OrbitCamera::up() const { return right().cross(forward()); }

Eigen::Matrix4f OrbitCamera::view() const {
  const Vec3 f = forward(), r = right(), u = up(), e = eye();
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = r.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -r.dot(e);
  m(1, 3) = -u.dot(e);
  m(2, 3) = f.dot(e);
  return m;
}

Eigen::Matrix4f OrbitCamera::projection(float aspect) const {
  const float n = 0.01f * distance, f = 100.0f * distance;
  const float t = 1.0f / std::tan(0.5f * fovY);
  Eigen::Matrix4f p = Eigen::Matrix4f::Zero();
  p(0, 0) = t / aspect;
  p(1, 1) = t;
  p(2, 2) = (f + n) / (n - f);
  p(2, 3) = 2.0f * f * n / (n - f);
  p(3, 2) = -1.0f;
  return p;
}

void OrbitCamera::frame(const Eigen::AlignedBox3f& box, float fill) {
  if (box.isEmpty()) return;
  target = box.center();
  const float radius = std::max(0.5f * box.diagonal().norm(), 1e-3f);
  distance = radius / std::sin(0.5f * fovY * fill);
}

void OrbitCamera::orbit(float dYaw, float dPitch) {
  yaw += dYaw;
  pitch = std::clamp(pitch + dPitch, -1.5f, 1.5f);
}

void OrbitCamera::zoom(float factor) { distance = std::clamp(distance * factor, 1e-3f, 1e4f); }

void OrbitCamera::pan(float dx, float dy) {
  const float height = 2.0f * distance * std::tan(0.5f * fovY);
  target += height * (-dx * right() + dy * up());
}

Ray OrbitCamera::ray(float x, float y, int width, int height) const {
  const float t = std::tan(0.5f * fovY);
  const float aspect = float(width) / float(std::max(height, 1));
  const float ndcX = 2.0f * x / float(width) - 1.0f, ndcY = 1.0f - 2.0f * y / float(height);
  return {eye(), (forward() + ndcX * t * aspect * right() + ndcY * t * up()).normalized()};
}

std::optional<Eigen::Vector2f> OrbitCamera::project(const Vec3& point, int width, int height) const {
  const Eigen::Vector4f clip = projection(float(width) / float(height)) * view() * point.homogeneous();
  if (clip.w() <= 0.0f) return std::nullopt;
  const float ndcX = clip.x() / clip.w(), ndcY = clip.y() / clip.w();
  return Eigen::Vector2f(0.5f * (ndcX + 1.0f) * float(width), 0.5f * (1.0f - ndcY) * float(height));
}

}  // namespace vrd
