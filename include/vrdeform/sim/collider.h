#pragma once
// Static colliders (ground plane, sphere, box) described by their signed distance.

#include <cstdint>

#include "vrdeform/math/types.h"

namespace vrd {

enum class ColliderShape : std::uint8_t { Plane, Sphere, Box };

struct Collider {
  ColliderShape shape = ColliderShape::Plane;
  Vec3 center = Vec3::Zero();        ///< plane: a point on it; sphere and box: the centre
  Vec3 normal = Vec3::UnitY();       ///< plane: unit normal pointing to the free side
  float radius = 0.0f;               ///< sphere radius
  Vec3 halfExtents = Vec3::Zero();   ///< box half sizes along its local axes
  Mat3 rotation = Mat3::Identity();  ///< box: local-to-world rotation
  float staticFriction = 0.5f;       ///< Coulomb mu_s: sticks while |f_t| <= mu_s f_n
  float dynamicFriction = 0.4f;      ///< Coulomb mu_k: sliding friction force = mu_k f_n
  float compliance = 0.0f;           ///< alpha of the normal contact (m/N); 0 = rigid

  static Collider plane(const Vec3& normal, const Vec3& pointOnPlane = Vec3::Zero());
  static Collider sphere(const Vec3& center, float radius);
  static Collider box(const Vec3& center, const Vec3& halfExtents, const Mat3& rotation = Mat3::Identity());
};

/// Signed distance from a point to the collider's surface (negative inside) and the outward
/// unit normal at the closest surface point.
struct SurfacePoint {
  float distance;
  Vec3 normal;
};

SurfacePoint closestSurface(const Collider& collider, const Vec3& p);

/// Throws vrd::Error when a collider has non-finite or non-positive sizes, a zero normal, a
/// non-orthonormal rotation or negative friction or compliance.
void validateCollider(const Collider& collider);

}  // namespace vrd
