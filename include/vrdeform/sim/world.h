#pragma once
// A simulation world: bodies, attachments, colliders and fingertips, stepped with XPBD
// (Algorithm 1) by a Gauss-Seidel solver that projects each colour of a body's constraints at once
// (SIMD lanes, threads) and everything else one at a time.

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "vrdeform/metrics/stage_times.h"
#include "vrdeform/sim/attachment.h"
#include "vrdeform/sim/body.h"
#include "vrdeform/sim/body_contact.h"
#include "vrdeform/sim/contact.h"
#include "vrdeform/sim/solver_settings.h"
#include "vrdeform/sim/surface_tree.h"

namespace vrd {

struct SolverTeam;
class ThreadTeam;
namespace sweeps {
struct LanePlan;
}

using AttachmentId = std::uint32_t;
using ColliderId = std::uint32_t;
using FingertipId = std::uint32_t;

/// Something the caller should know about, e.g. a body frozen after a NaN appeared.
struct SimEvent {
  std::uint64_t step;  ///< the step in which it happened (0-based)
  BodyId body;
  std::string message;
};

/// How much one constraint type still corrected in a step's last iteration: each particle's move
/// relative to its body's mean rest edge length, over the particles of the bodies that have the
/// type. 0 at a fixed point of the solver; NaN when not measured.
struct Residual {
  double rms = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

/// What the last call to step() did.
struct StepReport {
  std::uint64_t step = 0;  ///< index of the step (0-based)
  StageTimes times;        ///< summed over substeps and iterations
  /// Per constraint stage (Distance, Volume, Strain, StrainVolume, Bend, ShapeMatching, and Contact
  /// for every world constraint: attachments, collider and fingertip contacts), with
  /// SolverSettings::measureResiduals or a tolerance.
  std::array<Residual, kStageCount> residuals;
  int iterations = 0;    ///< Gauss-Seidel iterations run, summed over the substeps
  int coldSubsteps = 0;  ///< with SolverSettings::warmStart: substeps whose warm start moved too far, started cold
  std::size_t colliderContacts = 0;   ///< contacts that pushed (lambda > 0) in the last substep
  std::size_t fingertipContacts = 0;  ///< fingertip contacts (particles and triangles) that pushed in the last substep
  std::size_t bodyContacts = 0;       ///< body-body and self contacts that pushed in the last substep
  /// The farthest a vertex ended the step past a surface triangle it touches (m): 0 while every
  /// contact keeps its vertex on the outer side.
  float deepestPenetration = 0.0f;
};

class World {
 public:
  explicit World(const SolverSettings& settings = {});

  const SolverSettings& settings() const { return settings_; }
  void setSettings(const SolverSettings& settings);  ///< validated; takes effect at the next step
  float substepSize() const { return settings_.substepSize(); }

  // --- Bodies --------------------------------------------------------------------------------
  /// Adds a body whose particles start at rotation * rest + translation, at rest. The model is
  /// validated (vrd::Error on bad input) and may be shared by several bodies.
  BodyId addBody(std::shared_ptr<const BodyModel> model, const Vec3& translation = Vec3::Zero(),
                 const Quat& rotation = Quat::Identity());
  std::size_t bodyCount() const { return bodies_.size(); }
  const Body& body(BodyId id) const { return bodies_.at(id); }
  /// Puts a body back in its initial pose at rest and makes it active again.
  void resetBody(BodyId id);

  /// All particles. Positions (x) and velocities (v) may be written between steps, e.g. to move
  /// kinematic particles (w = 0), which follow their velocity, or to prescribe a grasp (eq. 35).
  Particles& particles() { return particles_; }
  const Particles& particles() const { return particles_; }
  Index particleIndex(BodyId body, Index local) const { return bodies_.at(body).firstParticle + local; }
  /// A particle's world position in double: its body's origin plus its position in the body's
  /// frame, which particles().x rounds to the float spacing of the world coordinate.
  Vec3d position(Index particle) const;
  /// Sets a particle's inverse mass; 0 makes it kinematic.
  void setInverseMass(Index particle, float w);
  /// Applies a constant force to every particle of a body: `force` (N) to each, plus `perKg`
  /// (m/s^2, N per kg) times the particle's mass, e.g. a wind that moves light and heavy particles
  /// alike. Kinematic particles get none of perKg.
  void setExternalForce(BodyId id, const Vec3& force, const Vec3& perKg = Vec3::Zero());

  // --- Attachments -----------------------------------------------------------------------------
  /// Holds a particle at `target` along the world axes set in `axes` (1 = held).
  AttachmentId attach(Index particle, const Vec3& target, float compliance = 0.0f, const Vec3& axes = Vec3::Ones(),
                      float damping = 0.0f);  // damping: beta of eq. 5; damps with tau = compliance * beta
  /// Moves an attachment's target to `goal` over the next step.
  void moveAttachment(AttachmentId id, const Vec3& goal);
  void detach(AttachmentId id);
  const Attachment& attachment(AttachmentId id) const { return attachments_.at(id); }
  /// Force the attachment applied to its particle in the last substep (N).
  Vec3 attachmentForce(AttachmentId id) const;

  // --- Colliders and fingertips ------------------------------------------------------------------
  ColliderId addCollider(const Collider& collider);
  const std::vector<Collider>& colliders() const { return colliders_; }

  /// Adds a kinematic contact sphere; `mode` says whether it touches the bodies' particles (the
  /// paper) or their surface triangles (BodyModel::surface).
  FingertipId addFingertip(const Vec3& center, float radius, float compliance = 0.0f,
                           FingertipContactMode mode = FingertipContactMode::Particles);
  /// Moves a fingertip's centre to `goal` over the next step.
  void moveFingertip(FingertipId id, const Vec3& goal);
  /// Switches a fingertip's contacts on or off; off, it passes through bodies (N(r) = {}, eq. 36).
  void setFingertipEnabled(FingertipId id, bool enabled);
  /// Switches what the fingertip touches; takes effect at the next substep.
  void setFingertipContactMode(FingertipId id, FingertipContactMode mode);
  /// Coulomb friction of the fingertip's contacts (none by default, as in the paper); throws for a
  /// negative or non-finite coefficient.
  void setFingertipFriction(FingertipId id, const FingertipFriction& friction);
  const Fingertip& fingertip(FingertipId id) const { return fingertips_.at(id); }
  std::size_t fingertipCount() const { return fingertips_.size(); }
  /// Total force the fingertip applied to the bodies in the last substep (N): (lambda n + friction
  /// lambda_t) / h^2 summed over its particle contacts, and the impulse its triangle contacts
  /// applied, / h^2.
  Vec3 fingertipForce(FingertipId id) const;
  /// Number of particles (or, in Triangles mode, surface triangles) the fingertip pushed in the
  /// last substep (contacts with lambda > 0).
  std::size_t fingertipContactCount(FingertipId id) const;
  /// Sum of |lambda^C| over the fingertip's contacts (of either mode) in the last substep: eq. 40's numerator.
  float fingertipLambdaSum(FingertipId id) const;

  const std::vector<ColliderContact>& colliderContacts() const { return colliderContacts_; }
  const std::vector<float>& colliderContactNormalLambda() const { return contactNormalLambda_; }
  const std::vector<Vec3>& colliderContactFrictionLambda() const { return contactFrictionLambda_; }
  const std::vector<FingertipContact>& fingertipContacts() const { return fingertipContacts_; }
  const std::vector<float>& fingertipContactLambda() const { return fingertipLambda_; }
  /// Contacts of fingertips in Triangles mode, and their multipliers (same order).
  const std::vector<FingertipTriangleContact>& fingertipTriangleContacts() const { return fingertipTriangleContacts_; }
  const std::vector<float>& fingertipTriangleContactLambda() const { return fingertipTriangleLambda_; }

  // --- Contact between bodies and within a body ------------------------------------------------------
  /// How a body touches other bodies and itself; throws vrd::Error for a negative or non-finite
  /// thickness, friction or compliance. By default bodies touch each other and not themselves.
  void setBodyContact(BodyId id, const BodyContactSettings& settings);
  const BodyContactSettings& bodyContact(BodyId id) const { return bodyContactSettings_.at(id); }
  /// Switches contact between two different bodies off (or back on); both must touch bodies too.
  void setPairContact(BodyId a, BodyId b, bool enabled);
  bool pairContact(BodyId a, BodyId b) const;
  /// The last substep's body contacts (ordered by key) and their normal multipliers (same order).
  const std::vector<BodyContact>& bodyContacts() const { return bodyContacts_; }
  const std::vector<float>& bodyContactLambda() const { return bodyContactLambda_; }
  /// Total force the contacts between body `by`'s surface and body `on`'s applied to `on` in the
  /// last substep, normal and friction (N); by == on: a body's self-contact, which nets to zero.
  Vec3 bodyContactForce(BodyId on, BodyId by) const;

  // --- Stepping ---------------------------------------------------------------------------------
  /// Advances the world by one time step: `substeps` x (predict, detect, `iterations` Gauss-Seidel
  /// sweeps, finalise).
  void step();
  const StepReport& lastStep() const { return report_; }
  std::uint64_t stepCount() const { return stepCount_; }
  /// Returns and clears the events since the last call.
  std::vector<SimEvent> takeEvents();

  // --- Measurements -------------------------------------------------------------------------------
  /// Sum of the signed volumes of the body's tets at its current positions (m^3).
  double volume(BodyId id) const;
  /// Heap memory a body takes (bytes): its model (rest data, constraints, colours), its state
  /// (multipliers, initial pose) and its particles (positions, predictions, velocities, forces).
  std::size_t bodyBytes(BodyId id) const;
  /// Volume loss e = (v0 - v)/v0 (paper section 6.1).
  double volumeLoss(BodyId id) const;
  /// Net constraint force on each of the body's particles in the last substep (N):
  /// sum over every constraint j acting on particle i of grad_i C_j lambda_j / h^2, including
  /// attachments and contacts (for fingertip triangle contacts, whose gradient turns with the
  /// triangle, the impulse applied: sum over the iterations of grad_i C dLambda, / h^2). At rest it
  /// balances the particle's weight and external force.
  std::vector<Vec3> particleConstraintForces(BodyId id) const;
  /// The same from the body's own constraints only (distance, volume, strain, bending, shape
  /// matching), without contacts and attachments: at rest it balances each particle's weight and
  /// whatever touches it, so it shows where a finger presses and where the ground holds the body.
  std::vector<Vec3> particleMaterialForces(BodyId id) const;

 private:
  void substeps(const SolverTeam& team);
  std::pair<Index, Index> particlesOf(const Body& b, const SolverTeam& team) const;
  void predict(float h, const SolverTeam& team);
  void detectContacts(const SolverTeam& team);
  void detectParticleContacts(const SolverTeam& team, std::vector<ColliderContact>& colliderContacts,
                              std::vector<FingertipContact>& fingertipContacts) const;
  void detectTriangleContacts();
  void prepareBodyContacts();
  void detectBodyContacts(const SolverTeam& team);
  struct ContactSides;  // two bodies' frames and settings, for the narrow phase
  ContactSides contactSides(BodyId a, BodyId b, std::vector<BodyContact>& found) const;
  void detectTrianglePair(const ContactSides& ab, const ContactSides& ba, Index t, Index u) const;  // a's t, b's u
  void detectVertexTriangle(const ContactSides& ab, Index vertex, Index triangle) const;  // a's vertex, b's triangle
  void detectEdgeEdge(const ContactSides& ab, Index e, Index f) const;                    // a's edge, b's edge
  bool touching(BodyId a, BodyId b) const;                               // the pair's settings let them touch
  Box3f sweptBox(Index particle, const Vec3& offset, float grow) const;  // start to prediction, grown
  void solveBodyContacts(float invH);
  void carryBodyContacts();  // warm start: carries their multipliers over and pushes by them
  float deepestPenetration() const;
  void resetMultipliers(const SolverTeam& team);
  void coldStart(BodyId id);                                             // zeroes the body's multipliers
  void warmStart(const sweeps::LanePlan& plan, const SolverTeam& team);  // moves the predictions by the multipliers
  bool warmPushesFit() const;  // the warm start moved no particle too far to be a guess
  void recordSubstepStart(const sweeps::LanePlan& plan, const SolverTeam& team);
  void solveIteration(float h, const sweeps::LanePlan& plan, const SolverTeam& team, bool measure);
  template <typename Sweep>
  void measured(Stage stage, const Body* body, bool measure, const SolverTeam& team, Sweep&& sweep);
  void solveWorldConstraints(float invH, bool timed, const SolverTeam& team);
  void finalise(float h, const SolverTeam& team);
  void containNonFinite(BodyId id);
  // Body frames: the world positions the caller moved, into their bodies' frames; the colliders
  // and fingertips into every body's frame (kept in step with the lists and the origins); each
  // frame re-centred and the world positions written.
  void ingest();
  void frameColliders();
  void frameFingertips(double from = 1.0, double to = 1.0);
  void publish();
  Vec3 framePosition(Index particle) const;
  const Collider& frameCollider(BodyId body, Index c) const { return frameColliders_[body * colliders_.size() + c]; }
  const Fingertip& frameFingertip(BodyId body, Index f) const {
    return frameFingertips_[body * fingertips_.size() + f];
  }

  SolverSettings settings_;
  Particles particles_;                     // the world view, written after each step
  std::vector<Point> local_;                // x: positions in their body's frame at the substep's start
  std::vector<Point> predicted_;            // p: the predictions the constraints correct, in the same frames
  std::vector<Point> inertial_;             // warm start: the predictions before any constraint moved them
  std::vector<BodyId> particleBody_;        // each particle's body
  std::vector<Collider> frameColliders_;    // colliders in each body's frame: [body * colliders + c]
  std::vector<Fingertip> frameFingertips_;  // fingertips in each body's frame: [body * fingertips + f]
  std::vector<Vec3d> fingertipFrom_;        // the fingertips' centres at the start of the step
  std::vector<Body> bodies_;
  std::vector<Attachment> attachments_;  // detached ones have particle == kNoParticle
  std::vector<Vec3> attachmentLambda_;
  std::vector<Collider> colliders_;
  std::vector<ColliderContact> colliderContacts_;
  std::vector<float> contactNormalLambda_;
  std::vector<Vec3> contactFrictionLambda_;
  std::vector<Fingertip> fingertips_;
  std::vector<FingertipContact> fingertipContacts_;
  std::vector<float> fingertipLambda_;
  std::vector<Vec3> fingertipFrictionLambda_;
  std::vector<FingertipTriangleContact> fingertipTriangleContacts_;
  std::vector<float> fingertipTriangleLambda_;
  std::vector<Vec3> fingertipTriangleFrictionLambda_;
  std::vector<std::array<Vec3, 3>> fingertipTriangleImpulse_;  // per corner: sum of grad C dLambda this substep
  // Body contact: each body's settings and surface, the pairs switched off, the contacts.
  struct ContactSurface {
    std::vector<Index> vertices;                  // the surface's vertices (body-local, ascending)
    std::vector<std::array<Index, 2>> edges;      // its edges (body-local, lower first, ascending)
    std::vector<std::array<Index, 2>> edgeFaces;  // per edge, its surface triangles (kNoFace: none)
    static constexpr Index kNoFace = ~Index(0);
    // Each vertex and edge belongs to one of its triangles (the first), whose pairs find it:
    // triangle t's are ownedVertices[vertexStart[t], vertexStart[t + 1]) (positions in `vertices`),
    // and likewise its edges (positions in `edges`).
    std::vector<Index> vertexStart, ownedVertices, edgeStart, ownedEdges;
    std::vector<std::array<Index, 3>> triangleCorners;  // each triangle's corners, as positions in `vertices`
    std::vector<std::array<Index, 2>> edgeCorners;      // each edge's, likewise
    SurfaceTree tree;                              // over the triangles: built on the rest shape, refitted each substep
    Index firstTriangleKey = 0, firstEdgeKey = 0;  // world-wide numbers of its first triangle and edge
  };
  static ContactSurface contactSurfaceOf(const BodyModel& model);
  void markCreases(BodyId id, std::size_t begin, std::size_t end);  // of its edges [begin, end)
  std::vector<BodyContactSettings> bodyContactSettings_;
  std::vector<ContactSurface> contactSurfaces_;
  std::vector<std::pair<BodyId, BodyId>> pairsOff_;  // (lower, higher), sorted
  std::vector<BodyContact> bodyContacts_;
  std::vector<float> bodyContactLambda_;
  std::vector<Vec3> bodyContactFrictionLambda_;
  // The broad phase of each body that takes part: its surface features' swept boxes in the frame
  // of the first such body, and, in self-contact, its triangles' normals (the tree's cones, the creases).
  struct ContactBroadPhase {
    std::vector<Box3f> boxes;                    // per surface triangle
    std::vector<Box3f> vertexBoxes, edgeBoxes;   // per surface vertex and edge
    std::vector<Vec3> startNormals, endNormals;  // per surface triangle, at the substep's start and predicted
    std::vector<char> sharp;                     // per surface edge of a body in self-contact: a crease
    std::vector<std::uint8_t> moving;            // per surface triangle: whether a corner moves
    Vec3 offset;                                 // the body's frame to the common one
  };
  std::vector<ContactBroadPhase> broadPhases_;  // per body
  // A substep's work (prepareBodyContacts): the bodies that take part, their trees' parts, and the
  // pairs of parts (of a body and itself, or of two bodies) to traverse.
  std::vector<BodyId> contactBodies_;
  std::vector<std::pair<BodyId, std::uint32_t>> contactParts_;
  struct ContactTask {
    BodyId a, b;
    std::uint32_t i, j;  // a's part and b's
  };
  std::vector<ContactTask> contactTasks_;
  // The last substep's contacts, whose multipliers a warm start carries over.
  std::vector<ColliderContact> previousColliderContacts_;
  std::vector<FingertipContact> previousFingertipContacts_;
  std::vector<FingertipTriangleContact> previousTriangleContacts_;
  std::vector<BodyContact> previousBodyContacts_;
  std::vector<SimEvent> events_;
  // A team's scratch: each member's contacts before the leader joins them (the leader's own go
  // straight to the lists), and which members found their share of each body finite.
  struct MemberContacts {
    std::vector<ColliderContact> collider;
    std::vector<FingertipContact> fingertip;
    std::vector<BodyContact> body;
  };
  std::vector<MemberContacts> memberContacts_;
  std::vector<std::uint8_t> memberFinite_;  // member k, body b at k * bodies + b
  // Shape matching's sums over fixed parts of a body's particles, added in order, so that a team
  // (each member summing some of the parts) gets the one-thread result.
  std::array<ShapeMatchSums, 4> shapeMatchSums_;
  StepReport report_;
  std::uint64_t stepCount_ = 0;
  // Residual measurement: positions before a type's sweep, and each stage's sum of squares,
  // count and largest relative move in the iteration measured.
  std::vector<Vec3> residualStart_;
  std::array<double, kStageCount> residualSumSq_{}, residualMax_{};
  std::array<std::size_t, kStageCount> residualCount_{};
  bool warm_ = false;       // this step's substeps start warm (SolverSettings::warmStart)
  bool converged_ = false;  // set by the leader in an adaptive iteration, read by all after a barrier
  // The solver's threads, made at the first step that uses them; a copy of the world makes its own.
  struct TeamSlot {
    std::unique_ptr<ThreadTeam> team;
    TeamSlot() = default;
    TeamSlot(const TeamSlot&);
    TeamSlot(TeamSlot&&) noexcept;
    TeamSlot& operator=(const TeamSlot&);
    TeamSlot& operator=(TeamSlot&&) noexcept;
    ~TeamSlot();
  };
  TeamSlot team_;
};

}  // namespace vrd
