#pragma once
// The built-in tetrahedraliser: isosurface stuffing (Labelle and Shewchuk 2007) on a
// body-centred cubic lattice. Lattice vertices close to the surface are warped onto it, tets
// the surface cuts are clipped to their inside part, and every boundary vertex ends on the
// surface, so the mesh's volume follows the surface's while the tets keep bounded angles.

#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/mesh/tet_pieces.h"

namespace vrd {

struct StuffingOptions {
  double cellSize = 0;  ///< edge of the lattice cubes; about 12 tets per cube, so count ~ 12 V / cellSize^3
  /// Boundary vertices lie on the surface, so the tets fill an inscribed solid that misses some
  /// volume (a few % at ~1,000 tets, shrinking as cellSize^2). With this set, they then move
  /// outward along their normals by the one uniform offset that restores the surface's volume
  /// (never far enough to invert a tet), so mass and inertia come out right.
  bool preserveVolume = true;
  std::size_t maxLatticeVertices = 50'000'000;
};

struct Stuffing {
  TetMesh mesh;
  /// A part of the solid thinner than about a cell can come out as fragments: loose, or joined to
  /// the rest only along an edge or at a vertex. They are dropped (keepOnePiecePerShell), so the
  /// mesh is one face-connected piece per solid, and counted here.
  DroppedPieces dropped;
};

/// Tetrahedralises the solid inside a closed, consistently oriented surface (check it first with
/// requireClosedSurface). All tets are positively oriented. Throws vrd::Error when the cell size
/// is not positive or the lattice would exceed `maxLatticeVertices`.
Stuffing stuffIsosurface(const TriMesh& surface, const StuffingOptions& options);

}  // namespace vrd
