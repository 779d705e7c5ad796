#include "vrdeform/haptics/baseline.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "vrdeform/error.h"

namespace vrd {

void validateBaselineSettings(const BaselineSettings& s) {
  if (!(std::isfinite(s.contactForce) && s.contactForce >= 0.0f && s.contactForce <= 1.0f))
    throw Error(fmt::format("baseline: contactForce must be in [0, 1], got {}", s.contactForce));
  if (!(std::isfinite(s.stiffness) && s.stiffness >= 0.0f))
    throw Error(fmt::format("baseline: stiffness must be finite and >= 0, got {}", s.stiffness));
}

float proxyDistance(std::span<const Collider> colliders, const Vec3& centre, float radius) {
  float depth = 0.0f;
  for (const Collider& c : colliders) depth = std::max(depth, radius - closestSurface(c, centre).distance);
  return std::isfinite(depth) ? depth : 0.0f;
}

float baselineForce(bool touching, float proxyDistance, const BaselineSettings& s) {
  const bool inside = proxyDistance > 0.0f;
  if (!touching && !inside) return 0.0f;
  const float value = s.contactForce + s.stiffness * (inside ? proxyDistance : 0.0f);
  return std::clamp(value, 0.0f, 1.0f);
}

}  // namespace vrd
