#pragma once
// PLY (ASCII, binary little- and big-endian) surface reader. Hand-written because Assimp 5.2's
// PLY importer hangs or aborts on truncated headers; every count here is checked against the
// bytes in the file before anything is allocated.

#include <filesystem>
#include <string>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Vertices in file order and polygons fanned into triangles; throws vrd::Error naming the
/// file and the problem. Indices are range-checked; coordinates are not (readSurface does).
TriMesh readPly(const std::filesystem::path& path, const std::string& bytes);

}  // namespace vrd
