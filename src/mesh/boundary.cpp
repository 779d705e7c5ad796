#include "vrdeform/mesh/boundary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>

#include "vrdeform/error.h"

namespace vrd {

std::vector<Triangle> boundaryFaces(const TetMesh& mesh) {
  // The faces of a positively oriented tet (a, b, c, d), each with its normal pointing outward.
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Entry {
    Triangle sorted;
    std::uint64_t where;  // tet * 4 + face
  };
  std::vector<Entry> entries;
  entries.reserve(mesh.tets.size() * 4);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    for (Index i : tet)
      if (i >= mesh.vertices.size())
        throw Error(fmt::format("tet {} refers to vertex {}, but there are only {} vertices", t + 1, std::size_t(i) + 1,
                                mesh.vertices.size()));
    for (int f = 0; f < 4; ++f) {
      Triangle key = {tet[kFace[f][0]], tet[kFace[f][1]], tet[kFace[f][2]]};
      std::sort(key.begin(), key.end());
      entries.push_back({key, t * 4 + f});
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& x, const Entry& y) {
    return x.sorted != y.sorted ? x.sorted < y.sorted : x.where < y.where;
  });
  std::vector<std::uint64_t> single;
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i + 1;
    while (j < entries.size() && entries[j].sorted == entries[i].sorted) ++j;
    if (j == i + 1) single.push_back(entries[i].where);
    i = j;
  }
  std::sort(single.begin(), single.end());

  std::vector<Triangle> faces;
  faces.reserve(single.size());
  for (std::uint64_t where : single) {
    const Tet& tet = mesh.tets[where / 4];
    const int* f = kFace[where % 4];
    Triangle tri = {tet[f[0]], tet[f[1]], tet[f[2]]};
    // An inverted tet lists its faces inward; flip them so that they point away from the fourth vertex.
    const auto p = [&](int k) -> Vec3T<double> { return mesh.vertices[tet[k]].cast<double>(); };
    if (signedTetVolume(p(0), p(1), p(2), p(3)) < 0) std::swap(tri[1], tri[2]);
    faces.push_back(tri);
  }
  return faces;
}

TriMesh boundarySurface(const TetMesh& mesh, std::vector<Index>* tetVertex) {
  TriMesh surface;
  std::vector<Index> remap(mesh.vertices.size(), ~Index{0});
  if (tetVertex) tetVertex->clear();
  for (Triangle f : boundaryFaces(mesh)) {
    for (Index& v : f) {
      if (remap[v] == ~Index{0}) {
        remap[v] = static_cast<Index>(surface.vertices.size());
        surface.vertices.push_back(mesh.vertices[v]);
        if (tetVertex) tetVertex->push_back(v);
      }
      v = remap[v];
    }
    surface.triangles.push_back(f);
  }
  return surface;
}

}  // namespace vrd
