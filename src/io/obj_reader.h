#pragma once
// Wavefront OBJ surface reader (the geometry: v and f). Hand-written because Assimp's OBJ importer
// allocates tens of megabytes for every file, however small, which a fuzzer cannot get past, and its
// messages name no line.

#include <string>
#include <string_view>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Vertices (v x y z, any further numbers ignored) in file order and faces (f with 3 or more corners
/// v, v/vt, v//vn or v/vt/vn; negative indices count back from the last vertex) fanned into
/// triangles; lines and points (l, p), texture coordinates, normals, groups, materials, smoothing
/// groups and other free-form keywords are read past. A line ending in a backslash continues on the
/// next. Throws vrd::Error "name:line: what" for a malformed number, a coordinate beyond float range
/// or a corner that refers to a vertex not defined above it.
TriMesh readObj(std::string_view text, const std::string& name);

}  // namespace vrd
