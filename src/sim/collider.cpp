#include "vrdeform/sim/collider.h"

#include <fmt/format.h>

#include "vrdeform/error.h"

namespace vrd {

Collider Collider::plane(const Vec3& normal, const Vec3& pointOnPlane) {
  Collider c;
  c.shape = ColliderShape::Plane;
  c.normal = normal.normalized();
  c.center = pointOnPlane;
  return c;
}

Collider Collider::sphere(const Vec3& center, float radius) {
  Collider c;
  c.shape = ColliderShape::Sphere;
  c.center = center;
  c.radius = radius;
  return c;
}

Collider Collider::box(const Vec3& center, const Vec3& halfExtents, const Mat3& rotation) {
  Collider c;
  c.shape = ColliderShape::Box;
  c.center = center;
  c.halfExtents = halfExtents;
  c.rotation = rotation;
  return c;
}

SurfacePoint closestSurface(const Collider& c, const Vec3& p) {
  switch (c.shape) {
    case ColliderShape::Plane:
      return {c.normal.dot(p - c.center), c.normal};
    case ColliderShape::Sphere: {
      const Vec3 d = p - c.center;
      const float length = d.norm();
      return {length - c.radius, length > 0.0f ? Vec3(d / length) : Vec3::UnitY()};
    }
    case ColliderShape::Box: {
      const Vec3 local = c.rotation.transpose() * (p - c.center);
      const Vec3 excess = local.cwiseAbs() - c.halfExtents;  // > 0 along axes where p is outside
      const Vec3 sign = local.unaryExpr([](float v) { return v < 0.0f ? -1.0f : 1.0f; });
      if ((excess.array() > 0.0f).any()) {
        const Vec3 outside = excess.cwiseMax(0.0f).cwiseProduct(sign);
        const float distance = outside.norm();
        return {distance, c.rotation * (outside / distance)};
      }
      int axis;
      const float distance = excess.maxCoeff(&axis);  // inside: nearest face
      return {distance, c.rotation * (sign[axis] * Vec3::Unit(axis))};
    }
  }
  return {0.0f, Vec3::UnitY()};
}

void validateCollider(const Collider& c) {
  if (!isFinite(c.center)) throw Error("collider: non-finite centre");
  if (c.shape == ColliderShape::Plane && !(isFinite(c.normal) && std::abs(c.normal.norm() - 1.0f) < 1e-3f))
    throw Error("collider: a plane needs a finite, non-zero normal");
  if (c.shape == ColliderShape::Sphere && !(std::isfinite(c.radius) && c.radius > 0.0f))
    throw Error(fmt::format("collider: sphere radius must be positive, got {}", c.radius));
  if (c.shape == ColliderShape::Box) {
    if (!(isFinite(c.halfExtents) && (c.halfExtents.array() > 0.0f).all()))
      throw Error("collider: box half extents must be positive");
    if (!(c.rotation.allFinite() && (c.rotation.transpose() * c.rotation - Mat3::Identity()).norm() < 1e-3f &&
          c.rotation.determinant() > 0.0f))
      throw Error("collider: box rotation must be a rotation matrix");
  }
  if (!(c.staticFriction >= 0.0f && c.dynamicFriction >= 0.0f && std::isfinite(c.staticFriction) &&
        std::isfinite(c.dynamicFriction)))
    throw Error("collider: friction coefficients must be finite and >= 0");
  if (!(std::isfinite(c.compliance) && c.compliance >= 0.0f))
    throw Error("collider: compliance must be finite and >= 0");
}

}  // namespace vrd
