#pragma once
// What a viewer (desktop window, headless renderer, VR page) draws of each body: a triangle
// surface whose vertices follow the body's particles. A body with a render mesh shows it, moved by
// its tets through the Embedding; a soft body without one shows its tet mesh's boundary; a cloth
// shows its triangles (two-sided).

#include <span>
#include <string>
#include <vector>

#include "vrdeform/scene/scene_builder.h"
#include "vrdeform/scene/snapshot.h"

namespace vrd {

struct ViewMesh {
  std::string name;                      ///< the body's name
  BodyId body = 0;                       ///< index into Snapshot::bodyFirst and BuiltScene::bodies
  BodyKind kind = BodyKind::Soft;        ///< a cloth is drawn from both sides
  std::vector<Triangle> triangles;       ///< indices into this mesh's own vertices
  const Embedding* embedding = nullptr;  ///< the render mesh's binding (owned by the scene), or null
  std::vector<Index> particles;          ///< without an embedding: the body particle of each vertex

  std::size_t vertexCount() const { return embedding ? embedding->vertexCount() : particles.size(); }
};

/// One ViewMesh per body of the scene, in body order. The result points into `scene` (the
/// embeddings), which must outlive it.
std::vector<ViewMesh> viewMeshes(const BuiltScene& scene);

/// Positions and unit normals of the mesh's vertices, from the positions of its body's particles
/// (`bodyPositions`: the body's slice, body-local order). Throws vrd::Error for spans of the wrong size.
void updateViewMesh(const ViewMesh& mesh, std::span<const Vec3> bodyPositions, std::span<Vec3> outPositions,
                    std::span<Vec3> outNormals);

/// The body's slice of a snapshot's positions.
std::span<const Vec3> bodyPositions(const Snapshot& snapshot, BodyId body);

}  // namespace vrd
