#pragma once
// Turns a SceneSpec into a running world: meshes read (surfaces tetrahedralised), placed and made
// into bodies, colliders, wind and pins, the bodies settled under gravity, the haptic scales
// calibrated, and the hand's input (actions or a script), whose actions aim at their bodies' tops.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/haptics/calibration.h"
#include "vrdeform/haptics/haptic_session.h"
#include "vrdeform/mesh/embedding.h"
#include "vrdeform/scene/scene_spec.h"
#include "vrdeform/sim/world.h"

namespace vrd {

/// Progress messages while building ("mesh: ...", "settled ..."); may be empty.
using SceneLog = std::function<void(std::string_view)>;

/// What a caller sees of buildScene while it works, and how it stops it (each member may be empty).
struct SceneBuildObserver {
  SceneLog log;
  /// After each settling step: the seconds settled and the seconds to settle.
  std::function<void(double done, double total)> settling;
  /// Polled before each run of the mesher, while TetGen runs, after each settling step and each
  /// step of the calibration poke: true ends the build with vrd::Stopped, saying where.
  std::function<bool()> stop;
};

/// A body's mesh as read, in the scene's placement.
struct PlacedMesh {
  TetMesh tets;            ///< soft bodies: the tets; cloth: the vertices only
  TriMesh surface;         ///< cloth: its triangles; soft bodies: empty
  TriMesh render;          ///< the render mesh, placed like the body (empty when none)
  std::uint64_t hash = 0;  ///< FNV-1a of the file's vertices and elements as read (before scaling)
};

/// Reads `body.mesh` (a surface is tetrahedralised for a soft body), scales, rotates and places it
/// as the spec says, and the render mesh with it. Throws vrd::Error naming the file, vrd::Stopped
/// when `stop` asks while meshing.
PlacedMesh placeBodyMesh(const BodySpec& body, const SceneLog& log = {}, const std::function<bool()>& stop = {});

/// The bounding box of a body's particles where they are now.
Eigen::AlignedBox3f bodyBounds(const World& world, BodyId body);

/// The top of a body: its highest particle; among those within 1% of the body's height of it (a
/// flat top), the one nearest the vertical through the middle of its bounding box.
Vec3 topPoint(const World& world, BodyId body);

struct SceneBody {
  std::string name;
  BodyKind kind = BodyKind::Soft;
  BodyId id = 0;
  std::shared_ptr<const BodyModel> model;
  PlacedMesh mesh;                     ///< at rest, as placed (before settling)
  std::optional<Embedding> embedding;  ///< render mesh bound to the tets
  Vec3 top = Vec3::Zero();             ///< topPoint() after settling
};

struct BuiltScene {
  SceneSpec spec;
  std::unique_ptr<World> world;
  std::vector<SceneBody> bodies;
  HapticSessionSettings session;  ///< the hand, grasp and haptic model (tau calibrated)
  std::optional<HapticCalibration> calibration;
  std::unique_ptr<HandInput> input;    ///< the scripted hand; null without a hand or a script/actions
  std::vector<HandAction> actions;     ///< the actions in world coordinates (empty with a script)
  double settleSeconds = 0.0;          ///< simulated while settling
  std::vector<SimEvent> settleEvents;  ///< NaN events while settling (a run's summary counts them)

  const SceneBody& body(std::string_view name) const;  ///< throws vrd::Error for an unknown name
};

/// Builds and settles the scene. Throws vrd::Error (naming the body or file) on bad input, a body
/// that does not settle to finite positions, or a failed calibration; vrd::Stopped when the
/// observer's stop asks.
BuiltScene buildScene(const SceneSpec& spec, const SceneBuildObserver& observer);
inline BuiltScene buildScene(const SceneSpec& spec, const SceneLog& log = {}) {
  return buildScene(spec, SceneBuildObserver{log, {}, {}});
}

}  // namespace vrd
