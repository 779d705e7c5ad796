#pragma once
// A soft cube resting on the ground, its weight carried by the ground contacts: the scene of
// docs/validation.md V12, shared by the contact tests.

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd::testing {

struct BlockOnGround {
  static constexpr float kG = 9.81f;
  static constexpr float kDensity = 1000.0f;

  World world;
  BodyId body = 0;
  float size, weight;

  /// A cube of side `side` in cells^3 cells (an even count puts a vertex at the top centre).
  explicit BlockOnGround(float side = 0.1f, int cells = 4, int substeps = 1)
      : world(settings(substeps)), size(side), weight(kDensity * side * side * side * kG) {
    Material m;
    m.elastic = ElasticModuli{2e4f, 0.3f, kDensity};
    const TetMesh mesh =
        makeBoxTets(Vec3(-0.5f * side, 0.0f, -0.5f * side), Vec3(side, side, side), cells, cells, cells);
    body = world.addBody(makeSoftBody(mesh, m, {false, true, true, false}));
    world.addCollider(Collider::plane(Vec3::UnitY()));
  }
  static SolverSettings settings(int substeps) {
    SolverSettings s;
    s.substeps = substeps;
    s.iterations = 20;
    s.linearDamping = 10.0f;
    return s;
  }
  /// Vertical force the ground pushes with, from the contact multipliers (its normal is +y).
  float groundReaction() const {
    const float h = world.substepSize();
    double sum = 0.0;
    for (float lambda : world.colliderContactNormalLambda()) sum += lambda;
    return float(sum / (h * h));
  }
  Vec3 position(Index local) const { return world.particles().x[world.particleIndex(body, local)].pos; }
};

}  // namespace vrd::testing
