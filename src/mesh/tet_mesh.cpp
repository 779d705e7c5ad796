#include "vrdeform/mesh/tet_mesh.h"

#include <fmt/format.h>

#include <algorithm>

#include "mesh/one_based.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

void checkVertices(const std::vector<Vec3>& vertices) {
  for (std::size_t v = 0; v < vertices.size(); ++v)
    if (!isFinite(vertices[v]))
      throw Error(fmt::format("vertex {} has a non-finite coordinate ({}, {}, {})", oneBased(v), vertices[v].x(),
                              vertices[v].y(), vertices[v].z()));
}

template <std::size_t N>
void checkIndices(const char* what, std::size_t element, const std::array<Index, N>& idx, std::size_t vertexCount) {
  for (std::size_t k = 0; k < N; ++k) {
    if (idx[k] >= vertexCount)
      throw Error(fmt::format("{} {} refers to vertex {}, but there are only {} vertices", what, oneBased(element),
                              oneBased(idx[k]), vertexCount));
    for (std::size_t j = 0; j < k; ++j)
      if (idx[j] == idx[k])
        throw Error(fmt::format("{} {} uses vertex {} twice ({})", what, oneBased(element), oneBased(idx[k]),
                                oneBasedList(idx)));
  }
}

}  // namespace

void validateTetMesh(const TetMesh& mesh) {
  if (mesh.tets.empty()) throw Error("tet mesh has no tetrahedra");
  checkVertices(mesh.vertices);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    checkIndices("tet", t, tet, mesh.vertices.size());
    Vec3T<double> p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.vertices[tet[k]].cast<double>();
    const double volume = signedTetVolume(p[0], p[1], p[2], p[3]);
    double longest = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (p[a] - p[b]).norm());
    const double shape = 6 * volume / (longest * longest * longest);
    if (std::abs(shape) < kDegenerateShape)
      throw Error(fmt::format("tet {} (vertices {}) is degenerate: rest volume {:.3g} for longest edge {:.3g}",
                              oneBased(t), oneBasedList(tet), volume, longest));
    if (volume < 0)
      throw Error(fmt::format("tet {} (vertices {}) is inverted: signed rest volume {:.3g} (swap two vertices)",
                              oneBased(t), oneBasedList(tet), volume));
  }
}

void validateTriMesh(const TriMesh& mesh) {
  if (mesh.triangles.empty()) throw Error("triangle mesh has no triangles");
  checkVertices(mesh.vertices);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    checkIndices("triangle", t, tri, mesh.vertices.size());
    const Vec3T<double> a = mesh.vertices[tri[0]].cast<double>(), b = mesh.vertices[tri[1]].cast<double>(),
                        c = mesh.vertices[tri[2]].cast<double>();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    if ((b - a).cross(c - a).norm() < kDegenerateShape * longest * longest)
      throw Error(fmt::format("triangle {} (vertices {}) is degenerate (zero area)", oneBased(t), oneBasedList(tri)));
  }
}

std::size_t removeUnusedVertices(TetMesh& mesh) {
  constexpr Index kUnused = ~Index{0};
  std::vector<Index> remap(mesh.vertices.size(), kUnused);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (Index v : mesh.tets[e]) {
      if (v >= remap.size())
        throw Error(fmt::format("tet {} refers to vertex {}, but there are only {} vertices", oneBased(e), oneBased(v),
                                remap.size()));
      remap[v] = 0;
    }
  std::vector<Vec3> kept;
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    if (remap[v] == 0) remap[v] = Index(kept.size()), kept.push_back(mesh.vertices[v]);
  const std::size_t dropped = mesh.vertices.size() - kept.size();
  if (dropped == 0) return 0;
  for (Tet& t : mesh.tets)
    for (Index& v : t) v = remap[v];
  mesh.vertices = std::move(kept);
  return dropped;
}

}  // namespace vrd
