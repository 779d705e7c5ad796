#pragma once
// Particle state of a world: flat arrays, float32, one entry per particle of every body.

#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

/// A position with the particle's inverse mass in the fourth lane, 16-byte aligned, so that one
/// load gives a constraint everything it needs from a particle (and SIMD gathers stay simple).
struct alignas(16) Point {
  Vec3 pos;
  float w;  ///< inverse mass (1/kg); 0 = kinematic (moved only by its velocity)
};

/// The world's view of its particles. The solver keeps each body's positions in the body's own
/// frame (Body::origin) and writes the world positions here after every step; a position written
/// here between steps moves the particle there.
struct Particles {
  std::vector<Point> x;     ///< world positions; x[i].w is the inverse mass
  std::vector<Vec3> v;      ///< velocities (m/s)
  std::vector<Vec3> force;  ///< constant external force on each particle (N), e.g. wind

  std::size_t size() const { return x.size(); }
};

}  // namespace vrd
