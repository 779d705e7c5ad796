#pragma once
// Surface -> tet mesh, with either mesher, after the surface checks, to a size bound or a tet
// count. The built-in mesher (isosurface stuffing) needs nothing else; TetGen (AGPL) runs as a
// separate program, so its licence stays apart from ours and a crash of it cannot take us down.

#include <filesystem>
#include <functional>
#include <string>

#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/mesh/tet_pieces.h"

namespace vrd {

enum class Mesher { Builtin, TetGen };

struct TetrahedraliseOptions {
  Mesher mesher = Mesher::Builtin;
  /// Aim for this many tets: the volume bound is searched until the count is within
  /// `countTolerance` of it. 0: use maxVolume.
  std::size_t targetTets = 0;
  double countTolerance = 0.15;
  /// Largest tet volume (TetGen -a; built-in: the volume of the lattice's tets). 0 with no
  /// target: none for TetGen, the surface's volume / 1000 for the built-in mesher.
  double maxVolume = 0;
  /// TetGen: largest circumradius / shortest edge (-q); 0 for none. Quality refinement adds tets,
  /// so when even an unbounded volume gives more than the target, the count search relaxes it
  /// to 2, then to none.
  double radiusEdge = 1.5;
  bool preserveVolume = true;            ///< built-in: see StuffingOptions
  std::string tetgenProgram = "tetgen";  ///< name in PATH, or a path
  double timeoutSeconds = 300;           ///< per TetGen run
  /// Polled before each run of the mesher and while TetGen runs: true ends meshing with vrd::Stopped
  /// (TetGen killed). Empty: never.
  std::function<bool()> stop = {};
};

struct Tetrahedralisation {
  TetMesh mesh;
  double maxVolume = 0;   ///< the bound of the run that was kept (0: none)
  double radiusEdge = 0;  ///< TetGen's quality bound of that run (0: none)
  int runs = 0;           ///< mesher runs the count search took
  /// Built-in mesher: fragments of parts thinner than about a lattice cell, dropped so that the
  /// mesh is one face-connected piece per solid (Stuffing::dropped); droppedMessage() words it.
  DroppedPieces dropped;
};

/// What a user is told of `result.dropped` ("" when nothing was dropped): how much went, why,
/// and that more tets keep it.
std::string droppedMessage(const Tetrahedralisation& result);

/// Checks the surface (requireClosedSurface) and tetrahedralises it; every tet comes out
/// positively oriented. Throws vrd::Error with the check's findings, for a TetGen that is
/// missing, fails, crashes or times out (with its last output), or for bad options.
Tetrahedralisation tetrahedralise(const TriMesh& surface, const TetrahedraliseOptions& options = {});

/// One TetGen run ("-pq<radiusEdge>a<maxVolume>zQ", each bound left out when 0) in a scratch
/// folder, tets oriented positively; no checks of the input.
TetMesh runTetGen(const TriMesh& surface, double maxVolume, double radiusEdge, const TetrahedraliseOptions& options);

const char* toString(Mesher mesher);

}  // namespace vrd
