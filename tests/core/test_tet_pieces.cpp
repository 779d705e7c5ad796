// Face-connected pieces of tet meshes, and keeping one piece per shell of a surface: built from
// boxes of tets placed to share a face, only an edge, or nothing.
#include <gtest/gtest.h>

#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/mesh/tet_pieces.h"

namespace vrd {
namespace {

// The tets of `b` added to `a`, with `b`'s vertices merged into `a`'s where they coincide.
TetMesh merged(TetMesh a, const TetMesh& b) {
  std::vector<Index> to(b.vertices.size());
  for (Index v = 0; v < b.vertices.size(); ++v) {
    to[v] = Index(a.vertices.size());
    for (Index w = 0; w < a.vertices.size(); ++w)
      if ((a.vertices[w] - b.vertices[v]).norm() < 1e-6f) to[v] = w;
    if (to[v] == a.vertices.size()) a.vertices.push_back(b.vertices[v]);
  }
  for (const Tet& t : b.tets) a.tets.push_back({to[t[0]], to[t[1]], to[t[2]], to[t[3]]});
  return a;
}

const TetMesh kBig = makeBoxTets(Vec3(0, 0, 0), Vec3(2, 2, 2), 2, 2, 2);

TEST(TetPieces, SharedFacesJoinEdgesAndVerticesDoNot) {
  EXPECT_EQ(facePieces(kBig).count, 1u);
  const TetMesh faceJoined = merged(kBig, makeBoxTets(Vec3(2, 0, 0), Vec3(1, 1, 1), 1, 1, 1));
  EXPECT_EQ(facePieces(faceJoined).count, 1u);
  const TetMesh edgeJoined = merged(kBig, makeBoxTets(Vec3(2, 2, 0), Vec3(1, 1, 1), 1, 1, 1));  // along z at (2, 2)
  const TetPieces e = facePieces(edgeJoined);
  EXPECT_EQ(e.count, 2u);
  for (std::size_t t = 0; t < kBig.tets.size(); ++t) EXPECT_EQ(e.of[t], e.of[0]);
  for (std::size_t t = kBig.tets.size(); t < edgeJoined.tets.size(); ++t) EXPECT_NE(e.of[t], e.of[0]);
  const TetMesh cornerJoined = merged(kBig, makeBoxTets(Vec3(2, 2, 2), Vec3(1, 1, 1), 1, 1, 1));
  EXPECT_EQ(facePieces(cornerJoined).count, 2u);
}

TEST(TetPieces, KeepsTheLargestPieceOfEachShell) {
  // One solid's surface: a fragment hinged on an edge and a loose one are dropped.
  TetMesh fragmented = merged(kBig, makeBoxTets(Vec3(2, 2, 0), Vec3(0.5f, 0.5f, 0.5f), 1, 1, 1));
  fragmented = merged(fragmented, makeBoxTets(Vec3(0.5f, 3, 0.5f), Vec3(0.25f, 0.25f, 0.25f), 1, 1, 1));
  const std::size_t bigTets = kBig.tets.size();
  const DroppedPieces d = keepOnePiecePerShell(fragmented, boundarySurface(kBig));
  EXPECT_EQ(d.pieces, 2u);
  EXPECT_EQ(fragmented.tets.size(), bigTets);
  EXPECT_EQ(d.tets, 2 * makeBoxTets(Vec3(0, 0, 0), Vec3(1, 1, 1), 1, 1, 1).tets.size());
  EXPECT_NEAR(d.share, (0.125 + 0.015625) / (8 + 0.125 + 0.015625), 1e-6);
  EXPECT_EQ(fragmented.vertices.size(), kBig.vertices.size());  // the fragments' vertices went with them
  EXPECT_EQ(facePieces(fragmented).count, 1u);

  // Two solids, two shells: each keeps its piece, however small.
  const TetMesh small = makeBoxTets(Vec3(5, 0, 0), Vec3(0.5f, 0.5f, 0.5f), 1, 1, 1);
  TetMesh two = merged(kBig, small);
  const TetMesh bothSurfaces = merged(kBig, small);
  const DroppedPieces none = keepOnePiecePerShell(two, boundarySurface(bothSurfaces));
  EXPECT_EQ(none.pieces, 0u);
  EXPECT_EQ(two.tets.size(), kBig.tets.size() + small.tets.size());
}

}  // namespace
}  // namespace vrd
