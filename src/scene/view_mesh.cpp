#include "vrdeform/scene/view_mesh.h"

#include <fmt/format.h>

#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/vertex_normals.h"

namespace vrd {

std::vector<ViewMesh> viewMeshes(const BuiltScene& scene) {
  std::vector<ViewMesh> meshes;
  for (const SceneBody& b : scene.bodies) {
    ViewMesh m{b.name, b.id, b.kind, {}, nullptr, {}};
    if (b.embedding) {
      m.triangles = b.mesh.render.triangles;
      m.embedding = &*b.embedding;
    } else if (b.kind == BodyKind::Cloth) {
      m.triangles = b.mesh.surface.triangles;
      m.particles.resize(b.mesh.tets.vertices.size());
      for (std::size_t i = 0; i < m.particles.size(); ++i) m.particles[i] = Index(i);
    } else {
      m.triangles = boundarySurface(b.mesh.tets, &m.particles).triangles;
    }
    meshes.push_back(std::move(m));
  }
  return meshes;
}

void updateViewMesh(const ViewMesh& mesh, std::span<const Vec3> bodyPositions, std::span<Vec3> outPositions,
                    std::span<Vec3> outNormals) {
  if (outPositions.size() != mesh.vertexCount() || (!outNormals.empty() && outNormals.size() != mesh.vertexCount()))
    throw Error(fmt::format("updateViewMesh {}: {} vertices, output for {}", mesh.name, mesh.vertexCount(),
                            outPositions.size()));
  if (mesh.embedding) {
    mesh.embedding->update(bodyPositions, outPositions, outNormals);  // checks bodyPositions' size
    return;
  }
  for (std::size_t v = 0; v < mesh.particles.size(); ++v) {
    if (mesh.particles[v] >= bodyPositions.size())
      throw Error(fmt::format("updateViewMesh {}: the body has {} particles, the mesh needs {}", mesh.name,
                              bodyPositions.size(), mesh.particles[v] + 1));
    outPositions[v] = bodyPositions[mesh.particles[v]];
  }
  if (!outNormals.empty()) computeVertexNormals(mesh.triangles, outPositions, outNormals);
}

std::span<const Vec3> bodyPositions(const Snapshot& snapshot, BodyId body) {
  if (body >= snapshot.bodyFirst.size())
    throw Error(fmt::format("bodyPositions: no body {} in a snapshot of {}", body, snapshot.bodyFirst.size()));
  const std::size_t first = snapshot.bodyFirst[body];
  const std::size_t end =
      body + 1 < snapshot.bodyFirst.size() ? snapshot.bodyFirst[body + 1] : snapshot.positions.size();
  return std::span<const Vec3>(snapshot.positions).subspan(first, end - first);
}

}  // namespace vrd
