#pragma once
// Checks on a triangle surface before it is tetrahedralised (or simulated as cloth): every defect
// is reported with its count and the faces where it is, instead of letting the mesher crash.

#include <cstddef>
#include <string>
#include <vector>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

enum class SurfaceDefect {
  Empty,                    ///< no faces
  NonFinite,                ///< a vertex coordinate is NaN, infinite or beyond +-1e15 (no digits left for its faces)
  BadIndex,                 ///< a face refers to a vertex that does not exist
  DegenerateFace,           ///< a repeated vertex index, or zero area (kDegenerateShape)
  NonManifoldEdge,          ///< an edge shared by three or more faces
  NonManifoldVertex,        ///< faces around a vertex form separate fans (touch at a point)
  BoundaryEdge,             ///< an edge of only one face: the surface is open
  InconsistentOrientation,  ///< two faces traverse their shared edge in the same direction
  SelfIntersection,         ///< two faces meet beyond the vertices or edge they share
  InwardOrientation,        ///< closed and consistent, but a component encloses negative volume
};

const char* toString(SurfaceDefect defect);

struct SurfaceIssue {
  SurfaceDefect defect;
  std::size_t count = 0;          ///< offending elements (faces, edges, vertices or face pairs)
  std::vector<Index> firstFaces;  ///< the first few offending faces (vertices for NonFinite)
  std::string message;            ///< says what and where
};

struct SurfaceReport {
  std::vector<SurfaceIssue> issues;
  std::size_t vertices = 0, faces = 0;
  std::size_t edges = 0, boundaryEdges = 0;
  std::size_t components = 0;  ///< groups of faces connected through edges
  double area = 0;
  double volume = 0;  ///< signed enclosed volume (positive: normals point out); meaningful when closed

  bool ok() const { return issues.empty(); }
  /// The first issue of this kind, or nullptr.
  const SurfaceIssue* find(SurfaceDefect defect) const;
  /// One line of figures, then one line per issue.
  std::string summary() const;
};

struct SurfaceCheckOptions {
  bool requireClosed = true;          ///< boundary edges are a defect (false for cloth)
  bool checkSelfIntersection = true;  ///< the costliest check: a BVH query per face
  std::size_t maxListed = 5;          ///< faces named per issue
};

/// Runs every check and reports what it finds; never throws for bad geometry or indices.
SurfaceReport checkSurface(const TriMesh& mesh, const SurfaceCheckOptions& options = {});

/// Throws vrd::Error with the report's messages unless the mesh is a clean closed surface.
void requireClosedSurface(const TriMesh& mesh);

/// Sum over faces of a.(b x c) / 6 in double; faces with out-of-range indices are skipped.
double enclosedVolume(const TriMesh& mesh);

}  // namespace vrd
