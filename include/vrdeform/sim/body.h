#pragma once
// Runtime state of one body in a world: where its particles are, its multipliers and its health.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "vrdeform/sim/body_model.h"

namespace vrd {

using BodyId = std::uint32_t;

enum class BodyState : std::uint8_t {
  Active,  ///< simulated
  Frozen,  ///< stopped after a non-finite value appeared; holds its last finite state
};

struct Body {
  std::shared_ptr<const BodyModel> model;
  Index firstParticle = 0;  ///< the body's particles are [firstParticle, firstParticle + particleCount)
  Index particleCount = 0;
  BodyState state = BodyState::Active;

  // Multipliers of the last substep, one per constraint in the model's order. lambda/h^2 with the
  // substep h is the constraint's generalised force: N for distances, N/m^2 for volumes, N m for
  // angles; the strain multipliers are per component (stretch 00, 11, 22, shear 01, 02, 12).
  std::vector<float> distanceLambda;
  std::vector<float> volumeLambda;
  StrainLambdas strainLambda;
  std::vector<float> bendLambda;
  std::vector<Vec3> shapeMatchLambda;
  /// F of each tet at the start of the substep, for the damping of its strain and volume
  /// constraints: coordinate d of column i of tet j at [(3 i + d) * tets + j]. Empty when the body
  /// has no strain constraints or they are undamped.
  std::vector<float> startDeformation;
  /// strain[j] and volume[j] of the model are on the same tet for every j, so that one pass can
  /// project both (SolverSettings::fuseStrainVolume); a hand-built model need not pair them.
  bool tetsPaired = false;
  Eigen::Quaterniond shapeMatchRotation = Eigen::Quaterniond::Identity();  ///< R of the last shape match (warm start)
  /// The shape-matching frame of the particles at the start of the substep, for its damping: the
  /// goals' own motion is no strain rate, so a body falling or turning freely is not damped.
  ShapeMatchFrame shapeMatchStart{Vec3::Zero(), Mat3::Identity()};

  /// Where the body's frame is: the solver keeps its particles' positions relative to this point,
  /// which follows the centre of mass of its moving particles, so that their float resolution is
  /// that of the body's size wherever the body is (docs/precision.md).
  Vec3d origin = Vec3d::Zero();
  Vec3d initialOrigin = Vec3d::Zero();
  std::vector<Vec3> initialPositions;  ///< in the frame at initialOrigin; resetBody() returns them at rest
  float lengthScale = 0.01f;           ///< mean rest edge length (m): residuals are relative to it
};

}  // namespace vrd
