#pragma once
// A random tet for the kernel tests (strain, strain + volume): rest corners in [-1, 1]^3, a state
// deformed by up to 0.2, inverse masses in [0, 2] with one particle kinematic in every seventh
// trial, each particle's motion in the substep, and its strain weights.

#include <random>

#include "vrdeform/sim/strain_constraint.h"

namespace vrd::testing {

struct RandomTet {
  Vec3 x[4], disp[4], a[4];
  float w[4];
  Mat3 restShape;  ///< D_rest: the rest edge vectors p2-p1, p3-p1, p4-p1

  /// Draws the next tet of `trial`; false when D_rest is too ill-conditioned to compare kernels on.
  bool draw(std::mt19937& rng, int trial) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), mass(0.0f, 2.0f);
    Vec3 rest[4];
    for (auto& r : rest) r = Vec3(u(rng), u(rng), u(rng));
    restShape << rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0];
    if (std::abs(restShape.determinant()) < 0.05f) return false;
    for (int k = 0; k < 4; ++k) {
      x[k] = rest[k] + 0.2f * Vec3(u(rng), u(rng), u(rng));
      w[k] = trial % 7 == k ? 0.0f : mass(rng);
      disp[k] = 0.01f * Vec3(u(rng), u(rng), u(rng));
    }
    const auto weights = strainWeights(Mat3(restShape.inverse()));
    for (int k = 0; k < 4; ++k) a[k] = weights[k];
    return true;
  }
};

}  // namespace vrd::testing
