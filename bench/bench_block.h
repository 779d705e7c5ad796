#pragma once
// The block the solver and contact benchmarks step: 10 x 10 x 20 cm of a soft material.

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/material.h"

namespace vrd {

inline Material benchMaterial() {
  Material m;
  m.elastic = ElasticModuli{2e4f, 0.4f, 1000.0f, 0.001f};
  return m;
}

/// A 10 cm x 10 cm x 20 cm block of about `tets` tets.
inline TetMesh benchBlock(int tets) { return makeBoxTetsNear(Vec3::Zero(), Vec3(0.1f, 0.1f, 0.2f), tets); }

}  // namespace vrd
