#include "vrdeform/mesh/tet_pieces.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <unordered_map>

#include "vrdeform/mesh/bvh.h"

namespace vrd {
namespace {

struct UnionFind {
  std::vector<Index> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), Index{0}); }
  Index find(Index x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(Index a, Index b) { parent[find(a)] = find(b); }
};

// Labels 0..count-1 from union-find roots, in order of first appearance.
std::size_t label(UnionFind& sets, std::vector<Index>& of) {
  std::unordered_map<Index, Index> number;
  for (Index i = 0; i < of.size(); ++i) of[i] = number.emplace(sets.find(i), Index(number.size())).first->second;
  return number.size();
}

struct FaceHash {
  std::size_t operator()(const std::array<Index, 3>& f) const {
    return (std::size_t(f[0]) * 73856093u) ^ (std::size_t(f[1]) * 19349663u) ^ (std::size_t(f[2]) * 83492791u);
  }
};

}  // namespace

TetPieces facePieces(const TetMesh& mesh) {
  UnionFind sets(mesh.tets.size());
  std::unordered_map<std::array<Index, 3>, Index, FaceHash> owner;
  owner.reserve(2 * mesh.tets.size());
  for (Index t = 0; t < mesh.tets.size(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<Index, 3> face;
      for (int k = 0, n = 0; k < 4; ++k)
        if (k != skip) face[n++] = mesh.tets[t][k];
      std::sort(face.begin(), face.end());
      if (const auto [it, added] = owner.emplace(face, t); !added) sets.join(t, it->second);
    }
  TetPieces pieces;
  pieces.of.resize(mesh.tets.size());
  pieces.count = label(sets, pieces.of);
  return pieces;
}

DroppedPieces keepOnePiecePerShell(TetMesh& mesh, const TriMesh& surface) {
  const TetPieces pieces = facePieces(mesh);
  if (pieces.count <= 1) return {};
  std::vector<double> volume(pieces.count, 0.0);
  for (Index t = 0; t < mesh.tets.size(); ++t) {
    const Tet& tet = mesh.tets[t];
    volume[pieces.of[t]] += std::abs(double(
        signedTetVolume(mesh.vertices[tet[0]], mesh.vertices[tet[1]], mesh.vertices[tet[2]], mesh.vertices[tet[3]])));
  }

  // The surface's shells, and each piece's: the shell nearest most of its vertices.
  UnionFind shellSets(surface.vertices.size());
  for (const Triangle& f : surface.triangles) shellSets.join(f[0], f[1]), shellSets.join(f[0], f[2]);
  std::vector<Index> shellOf(surface.vertices.size());
  const std::size_t shells = label(shellSets, shellOf);
  std::vector<Index> shellOfPiece(pieces.count, 0);
  if (shells > 1) {
    std::vector<Box3d> points(surface.vertices.size());
    for (std::size_t v = 0; v < points.size(); ++v) points[v] = Box3d(surface.vertices[v].cast<double>());
    const Bvh tree(points);
    std::vector<std::vector<std::size_t>> votes(pieces.count, std::vector<std::size_t>(shells, 0));
    std::vector<Index> pieceOfVertex(mesh.vertices.size(), ~Index{0});
    for (Index t = 0; t < mesh.tets.size(); ++t)
      for (Index v : mesh.tets[t]) pieceOfVertex[v] = pieces.of[t];
    for (Index v = 0; v < mesh.vertices.size(); ++v) {
      if (pieceOfVertex[v] == ~Index{0}) continue;
      const Vec3d p = mesh.vertices[v].cast<double>();
      const Index nearest =
          tree.nearest([&](const Box3d& box) { return box.squaredExteriorDistance(p); },
                       [&](Index s) { return (surface.vertices[s].cast<double>() - p).squaredNorm(); })
              .first;
      ++votes[pieceOfVertex[v]][shellOf[nearest]];
    }
    for (std::size_t p = 0; p < pieces.count; ++p)
      shellOfPiece[p] = Index(std::max_element(votes[p].begin(), votes[p].end()) - votes[p].begin());
  }
  std::vector<Index> keep(shells, ~Index{0});  // per shell, its largest piece
  for (Index p = 0; p < pieces.count; ++p)
    if (Index& k = keep[shellOfPiece[p]]; k == ~Index{0} || volume[p] > volume[k]) k = p;

  DroppedPieces dropped;
  std::vector<bool> kept(pieces.count, false);
  for (Index k : keep)
    if (k != ~Index{0}) kept[k] = true;
  for (std::size_t p = 0; p < pieces.count; ++p)
    if (!kept[p]) ++dropped.pieces, dropped.share += volume[p];
  dropped.share /= std::accumulate(volume.begin(), volume.end(), 0.0);
  std::size_t n = 0;
  for (Index t = 0; t < mesh.tets.size(); ++t)
    if (kept[pieces.of[t]]) mesh.tets[n++] = mesh.tets[t];
  dropped.tets = mesh.tets.size() - n;
  mesh.tets.resize(n);
  removeUnusedVertices(mesh);
  return dropped;
}

}  // namespace vrd
