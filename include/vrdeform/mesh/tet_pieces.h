#pragma once
// The pieces of a tet mesh: tets sharing a face (three vertices) belong to one piece. Tets that
// touch only along an edge or at a vertex are in different pieces, as loose islands are: a body
// of several pieces falls apart or hinges, so a mesher that should give one solid checks this.

#include <cstddef>
#include <vector>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

struct TetPieces {
  std::vector<Index> of;  ///< per tet, its piece in [0, count)
  std::size_t count = 0;
};

/// Labels the face-connected pieces of `mesh` (its tets' vertex indices; no geometry).
TetPieces facePieces(const TetMesh& mesh);

/// What keepOnePiecePerShell dropped.
struct DroppedPieces {
  std::size_t pieces = 0, tets = 0;
  double share = 0;  ///< their share of the mesh's volume
};

/// Keeps, for each shell of `surface` (its vertex-connected components: the outer surfaces of
/// separate solids, or a hollow solid's inner surface), the largest piece of `mesh` by volume
/// next to it, and drops every other piece and the vertices no kept tet uses. For a mesh of
/// `surface`'s solid made from a lattice coarser than some feature, the dropped pieces are that
/// feature's loose or edge-joined fragments.
DroppedPieces keepOnePiecePerShell(TetMesh& mesh, const TriMesh& surface);

}  // namespace vrd
