#pragma once
// What a scene file says (docs/scenes.md): bodies, colliders, solver, the hand and its scripted
// interaction, haptic parameters and the run's outputs. Plain data, checked by the parser
// (scene_file.h) and turned into a world by buildScene() (scene_builder.h).

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/grasp.h"
#include "vrdeform/interact/hand_actions.h"
#include "vrdeform/interact/hand_rig.h"
#include "vrdeform/io/tetrahedralise.h"
#include "vrdeform/sim/body_contact.h"
#include "vrdeform/sim/body_model.h"
#include "vrdeform/sim/collider.h"
#include "vrdeform/sim/solver_settings.h"

namespace vrd {

enum class BodyKind { Soft, Cloth };
/// Where a body goes: `Ground` scales it, then puts its lowest point on y = 0 with its bounding box
/// centred over `position` (x, z); `AsIs` scales, rotates and adds `position` to its coordinates.
enum class Placement { Ground, AsIs };

struct BodySpec {
  std::string name;                           ///< unique in the scene; the interaction names bodies by it
  BodyKind kind = BodyKind::Soft;             ///< soft: tets; cloth: an open or closed triangle surface
  std::string mesh;                           ///< surface (tetrahedralised) or tet mesh; absolute path once loaded
  std::string renderMesh;                     ///< optional finer surface driven by the tets (embedding.h); absolute
  float scale = 1.0f;                         ///< applied to the mesh (and render mesh) coordinates first
  std::array<float, 3> rotationDeg{0, 0, 0};  ///< then rotated about x, then y, then z (degrees)
  Vec3 position = Vec3::Zero();
  Placement placement = Placement::Ground;
  TetrahedraliseOptions mesher;  ///< for a surface: mesher, targetTets (0 keeps the default), maxVolume
  ConstraintSet constraints = ConstraintSet::paper();
  Material material;  ///< compliance form, or moduli when material.elastic is set
  /// Cloth: particles held fixed, given as the side of the bounding box they lie on within
  /// `pinTolerance` (m), e.g. "-x" for the flag's pole. Empty: none.
  std::vector<std::string> pin;
  float pinTolerance = 1e-3f;
  Vec3 force = Vec3::Zero();  ///< constant force on every particle (N); the scene's wind adds to cloth
  /// Another (earlier) body this one is placed on: its lowest point the two thicknesses above the
  /// highest point of that body under it (x and z as `placement` says). Empty: none.
  std::string on;
  BodyContactSettings contact;  ///< how it touches other bodies and itself
};

/// One scripted action of the hand (hand_actions.h) on a body, timed from the end of the settling
/// phase and aimed at that body's top where it is when the action starts.
struct ActionSpec {
  std::string body;  ///< empty: the first body
  /// Moves the target from the body's top along x and z (m), down to the highest particle within two
  /// fingertip radii of that vertical (where a fingertip coming down meets the body); y is unused.
  Vec3 offset = Vec3::Zero();
  HandAction action;  ///< its target is set when the scene is built
};

struct HandSpec {
  bool enabled = true;
  HandRigSettings rig = HandRigSettings::g1();  ///< g1 or pro, fingertip radius, contact mode
  GraspSettings grasp;
  std::string script;  ///< a hand script (docs/hand-input.md), absolute; replaces `actions`
  std::vector<ActionSpec> actions;
};

struct HapticsSpec {
  HapticSettings settings;
  bool calibrate = true;  ///< calibrateHaptics() on the first soft body after settling
};

struct OutputSpec {
  double meshEvery = 0.1;  ///< s between deformed-mesh frames (.vtu/.pvd); 0: none
  bool plots = true;       ///< force against time and against indentation, SVG
};

struct SceneSpec {
  std::string name;         ///< e.g. "liver"
  std::string description;  ///< one line
  std::string source;       ///< the file it came from (absolute), or "builtin:NAME"
  SolverSettings solver;
  /// Constant acceleration (m/s^2: N per kg of each particle's mass) of every cloth particle; the
  /// paper's flag: 20 N on each 1 kg particle.
  Vec3 wind = Vec3::Zero();
  double settle = 1.0;  ///< s the bodies settle under gravity before the interaction (not in the run's time)
  /// Settling ends once every particle has moved slower than kRestSpeed for 0.2 s (after at least
  /// 0.5 s), `settle` being then the most it takes. Scene files settle so unless they give `settle`.
  bool settleToRest = false;
  static constexpr double kRestSpeed = 0.005;        ///< m/s
  static constexpr double kSettleToRestMost = 20.0;  ///< s, a scene file's `settle` when it gives none
  double seconds = 6.0;                              ///< default length of a run after settling
  std::vector<BodySpec> bodies;
  std::vector<Collider> colliders;  ///< the ground is one, if wanted
  /// Pairs of bodies (by name) that pass through each other; every other pair of bodies that
  /// touch bodies touches.
  std::vector<std::array<std::string, 2>> noContact;
  HandSpec hand;
  HapticsSpec haptics;
  OutputSpec output;
};

}  // namespace vrd
