#pragma once
// A body's rest data and constraint arrays: computed once per mesh and material, immutable while
// simulating, and shared by every body instance made from it. Runtime state lives in Body.

#include <memory>
#include <optional>
#include <vector>

#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/sim/bend_constraint.h"
#include "vrdeform/sim/distance_constraint.h"
#include "vrdeform/sim/material.h"
#include "vrdeform/sim/shape_matching.h"
#include "vrdeform/sim/strain_constraint.h"
#include "vrdeform/sim/volume_constraint.h"

namespace vrd {

/// Which constraints a soft body gets from its tet mesh.
struct ConstraintSet {
  bool edges = false;         ///< a distance constraint per tet edge
  bool volume = true;         ///< one per tet (eqs. 16-23)
  bool strain = true;         ///< six per tet (eqs. 29-34)
  bool shapeMatching = true;  ///< one per body (eqs. 25-28)

  static ConstraintSet paper() { return {}; }  ///< volume + strain + shape matching (paper Table 1)
  static ConstraintSet edgesAndVolume() { return {true, true, false, false}; }
};

/// The order in which the solver projects a body's constraints.
enum class SolveOrder {
  Coloured,  ///< by colour (constraint_colouring.h): SIMD lanes and threads
  Mesh,      ///< the mesh's order, one at a time: the plain Gauss-Seidel reference
};

/// Damping time tau = alpha * beta (s) of each constraint type; gamma = tau / h (xpbd.h).
struct ConstraintDamping {
  float distance = 0, volume = 0, strainStretch = 0, strainShear = 0, bend = 0, shapeMatching = 0;
};

struct BodyModel {
  std::vector<Vec3> restPositions;  ///< body-local rest positions
  std::vector<float> invMass;       ///< inverse masses (1/kg), 0 = kinematic
  std::vector<Tet> tets;            ///< the volume elements (soft bodies), in solver order; volume[j] and
                                    ///< strain[j], when present, belong to tets[j]
  std::vector<Triangle> triangles;  ///< the cloth triangles (cloth)
  std::vector<Triangle> surface;    ///< outward surface triangles that fingertips in Triangles mode touch: a
                                    ///< soft body's boundaryFaces(), a cloth's triangles; may be empty

  std::vector<DistanceConstraint> distance;
  std::vector<VolumeConstraint> volume;
  std::vector<StrainConstraint> strain;
  std::vector<BendConstraint> bend;
  std::optional<ShapeMatchModel> shapeMatching;

  /// Colours (constraint_colouring.h) of the distance array and of the tet-order arrays (volume,
  /// strain): the solver projects a colour's constraints at once, in SIMD lanes and across threads,
  /// and the rest one at a time. Empty (hand-built models, SolveOrder::Mesh): all one at a time.
  std::vector<std::uint32_t> distanceColours, tetColours;
  /// Their groups (Colouring::groupColours, twoThreadGroups): a big body is cut in halves that two
  /// threads sweep at once, without waiting for each other after every colour. Empty: not cut.
  std::vector<std::uint32_t> distanceGroups, tetGroups;
  /// The bending array's levels (levelOrder, colours that keep the mesh's order): a level's
  /// constraints run at once, in SIMD lanes, with the result of the mesh order one at a time, whose
  /// faster convergence a cloth at few iterations relies on. Empty: all one at a time.
  std::vector<std::uint32_t> bendLevels;

  ConstraintDamping damping;
  float particleRadius = 0.0f;  ///< contact offset against colliders (m)
  double restVolume = 0.0;      ///< sum of the tets' rest volumes (m^3)

  std::size_t particleCount() const { return restPositions.size(); }
  /// Heap memory of the rest data and constraint arrays (capacity, bytes).
  std::size_t bytes() const;
};

/// Builds a soft body from a tet mesh. Throws vrd::Error naming the element for a degenerate or
/// inverted rest tet, a non-finite coordinate, an out-of-range index or an invalid material.
std::shared_ptr<const BodyModel> makeSoftBody(const TetMesh& mesh, const Material& material,
                                              const ConstraintSet& constraints = ConstraintSet::paper(),
                                              SolveOrder order = SolveOrder::Coloured);

/// Builds a cloth from a triangle mesh: a distance constraint per edge and a bending constraint
/// per interior edge. Needs a compliance material (no moduli).
std::shared_ptr<const BodyModel> makeCloth(const TriMesh& mesh, const Material& material,
                                           SolveOrder order = SolveOrder::Coloured);

/// Appends a distance constraint whose rest length is the rest distance of particles a and b.
void addDistanceConstraint(BodyModel& model, Index a, Index b, float compliance);

/// Builds the shape-matching rest frame from the model's rest positions and masses.
ShapeMatchModel makeShapeMatchModel(const BodyModel& model, float compliance);

/// Checks a hand-built or loaded model: finite positions, inverse masses finite and >= 0,
/// constraint, tet, triangle and surface triangle indices in range, finite non-negative compliances. Throws vrd::Error
/// naming the item.
void validateModel(const BodyModel& model);

}  // namespace vrd
