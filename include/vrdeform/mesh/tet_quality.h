#pragma once
// Quality figures of a tetrahedral mesh: element shape (dihedral angles, radius-edge ratio),
// inverted and degenerate elements, boundary, and volume against the surface it was made from.

#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

struct TetQuality {
  std::size_t vertices = 0, tets = 0;
  std::size_t unusedVertices = 0;    ///< referenced by no valid tet
  std::size_t boundaryFaces = 0;     ///< faces of exactly one tet
  std::size_t nonManifoldFaces = 0;  ///< faces of three or more tets
  std::size_t invalid = 0;           ///< out-of-range or repeated index, or a non-finite coordinate: skipped
  std::size_t degenerate = 0;        ///< 6|V| / l_max^3 < kDegenerateShape: no angles or ratios
  std::size_t inverted = 0;          ///< negative volume among the others
  /// Interior angles between the faces at each edge, over non-degenerate tets (0 when there are
  /// none); a regular tet has acos(1/3) = 70.53 degrees at all six edges.
  double minDihedralDeg = 0, maxDihedralDeg = 0;
  /// Circumradius / shortest edge over non-degenerate tets; a regular tet has sqrt(6)/4 = 0.612.
  double minRadiusEdge = 0, maxRadiusEdge = 0, meanRadiusEdge = 0;
  std::array<std::size_t, 18> dihedralHistogram{};  ///< dihedral angles in 10-degree bins
  double volume = 0;                                ///< sum of signed tet volumes
  std::optional<double> surfaceVolume;              ///< enclosed volume of the surface given to measureTetQuality
  std::optional<double> volumeError;                ///< (volume - surfaceVolume) / |surfaceVolume|

  /// A human-readable multi-line report.
  std::string table() const;
};

/// Measures every tet; never throws for bad elements (they are counted instead).
TetQuality measureTetQuality(const TetMesh& mesh, const TriMesh* surface = nullptr);

}  // namespace vrd
