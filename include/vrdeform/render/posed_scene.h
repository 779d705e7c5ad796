#pragma once
// A built scene's view meshes posed by one snapshot, on the CPU: vertex positions and normals, an
// optional colour-map value per vertex, each body's volume change, and ray picking for the mouse.
// It reads only snapshots and the scene's static parts (meshes, embeddings, colliders), never
// the world, so a render thread can use it while the simulation loop runs.

#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "vrdeform/render/orbit_camera.h"
#include "vrdeform/scene/view_mesh.h"

namespace vrd {

/// What colours the bodies.
enum class ColorMap {
  None,          ///< each body its own colour
  Strain,        ///< mean stretch of the edges at each vertex, l / l0 - 1
  VolumeChange,  ///< mean relative volume change of the tets at each vertex, V / V0 - 1
  /// |net force of the body's own constraints| on each particle (N), Snapshot::constraintForce:
  /// at rest each particle's weight, more where a finger presses, the ground holds or a grasp pulls.
  ConstraintForce,
};

/// "none", "strain", "volume", "force".
std::string_view colorMapName(ColorMap map);
/// |value| a map draws at full colour by default: 2% strain or volume change; for force, three
/// times the median of `settled`'s (the bodies at rest, constraint forces captured), about three
/// particles' weight, so a poke, the ground's support or a grasp stands out.
float defaultColorRange(ColorMap map, const Snapshot& settled);
/// The inverse of colorMapName; nothing for another word.
std::optional<ColorMap> parseColorMap(std::string_view name);

struct RayHit {
  float distance = 0.0f;  ///< along the ray (m)
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();  ///< of the triangle hit, facing the ray's origin
  BodyId body = 0;
};

class PosedScene {
 public:
  /// Takes what it needs from `scene` (which must outlive it: the embeddings stay there).
  explicit PosedScene(const BuiltScene& scene);

  /// Poses every mesh as `snapshot` has the bodies and computes `map`'s values (ConstraintForce
  /// reads snapshot.constraintForce: zeros when the snapshot has none). Throws vrd::Error for a
  /// snapshot of another world (other particle or body counts).
  void pose(const Snapshot& snapshot, ColorMap map);

  std::size_t meshCount() const { return meshes_.size(); }
  const ViewMesh& mesh(std::size_t i) const { return meshes_[i]; }
  std::span<const Vec3> positions(std::size_t i) const { return posed_[i].positions; }
  std::span<const Vec3> normals(std::size_t i) const { return posed_[i].normals; }
  /// The colour map's value at each vertex (zeros for ColorMap::None).
  std::span<const float> values(std::size_t i) const { return posed_[i].values; }
  const std::vector<Collider>& colliders() const { return colliders_; }
  /// The posed meshes' bounding box (the bodies at rest before the first pose()).
  const Eigen::AlignedBox3f& bounds() const { return bounds_; }
  /// (V0 - V) / V0 of a soft body as posed, V from its tets; 0 for a cloth.
  double volumeLoss(BodyId body) const { return bodies_.at(body).volumeLoss; }

  /// The nearest posed triangle the ray crosses.
  std::optional<RayHit> pick(const Ray& ray) const;

 private:
  struct Edge {
    Index a, b;
    float restLength;
  };
  struct BodyRest {  // one body's rest data for the colour maps and its volume
    std::vector<Edge> edges;
    std::vector<Tet> tets;  // the placed tet mesh's, whose numbering the embedding uses
    std::vector<float> restVolume;
    std::vector<float> edgeCount, tetCount;  // per particle
    double totalRestVolume = 0.0;
    double volumeLoss = 0.0;
    std::vector<float> particleValues;  // scratch, per particle
  };
  struct Posed {
    std::vector<Vec3> positions, normals;
    std::vector<float> values;
  };

  void particleValues(BodyRest& body, std::span<const Vec3> x, std::span<const float> force, ColorMap map) const;

  std::vector<ViewMesh> meshes_;
  std::vector<BodyRest> bodies_;
  std::vector<Posed> posed_;
  std::vector<Collider> colliders_;
  std::size_t particles_ = 0;
  Eigen::AlignedBox3f bounds_;
};

}  // namespace vrd
