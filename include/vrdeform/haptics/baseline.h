#pragma once
// The paper's condition B (section 6.3): the vendor SDK's force, computed from the distance
// between the tracked fingertip and its proxy (the virtual fingertip that colliders stop) with a
// fixed stiffness. Rigid colliders stop the proxy, so pressing one gives a graded force; a soft
// body gives way, the distance stays zero and the force is a constant while touching: the binary,
// step-like signal the paper's participants rated lower. Kept for A/B studies.

#include <span>

#include "vrdeform/math/types.h"
#include "vrdeform/sim/collider.h"

namespace vrd {

struct BaselineSettings {
  float contactForce = 0.5f;  ///< value while touching with zero proxy distance (the SDK's preset)
  float stiffness = 100.0f;   ///< value per metre of tracked-to-proxy distance (1/m)
};

/// Throws vrd::Error for negative or non-finite values.
void validateBaselineSettings(const BaselineSettings& settings);

/// How far a fingertip sphere (centre, radius) has gone into the static colliders: the distance
/// between it and a proxy the colliders stop (m), 0 when clear.
float proxyDistance(std::span<const Collider> colliders, const Vec3& centre, float radius);

/// clip(contactForce + stiffness * proxyDistance, 0, 1) while touching, 0 otherwise.
float baselineForce(bool touching, float proxyDistance, const BaselineSettings& s);

}  // namespace vrd
