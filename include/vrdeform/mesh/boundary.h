#pragma once
// The boundary surface of a tet mesh.

#include <vector>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// The faces that belong to exactly one tet, as triangles indexing the tet mesh's own vertices (no
/// renumbering), each oriented outward: its normal (b-a)x(c-a) points away from the tet's fourth
/// vertex. Order: by tet, then by the face's place in the tet, so the result is deterministic.
/// A face shared by three or more tets (non-manifold input) is not a boundary face.
/// Throws vrd::Error for an index out of range.
std::vector<Triangle> boundaryFaces(const TetMesh& mesh);

/// The boundary as a surface of its own: boundaryFaces() with only the vertices they use, numbered
/// in order of first use. `tetVertex` (optional) receives, per surface vertex, its tet-mesh vertex.
TriMesh boundarySurface(const TetMesh& mesh, std::vector<Index>* tetVertex = nullptr);

}  // namespace vrd
