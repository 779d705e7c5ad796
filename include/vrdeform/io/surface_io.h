#pragma once
// Triangle surfaces in and out: OBJ, OFF, STL (ASCII and binary) and PLY (ASCII and binary).

#include <filesystem>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Whether the extension names a surface format (.obj, .off, .stl, .ply, any case).
bool isSurfaceFile(const std::filesystem::path& path);

/// Reads a surface (the format from the extension; STL binary or ASCII from the content).
/// Polygons are triangulated, and corners at identical positions become one vertex (STL stores
/// none shared; OBJ seams split them), numbered in order of first use by a face; vertices no face
/// uses are dropped. Throws vrd::Error for a missing, unreadable, truncated or malformed file, a
/// file without triangles, or a non-finite coordinate.
TriMesh readSurface(const std::filesystem::path& path);

struct SurfaceWriteOptions {
  bool binary = true;  ///< STL and PLY: binary (little-endian) or ASCII
};

/// Throws vrd::Error unless writeSurface knows `path`'s extension: refuses an output before the
/// work that makes it.
void checkSurfaceOutput(const std::filesystem::path& path);

/// Writes by extension (.obj, .off, .stl, .ply), all or nothing. Throws vrd::Error for an
/// unknown extension, an invalid mesh or a failed write.
void writeSurface(const std::filesystem::path& path, const TriMesh& mesh, const SurfaceWriteOptions& options = {});

}  // namespace vrd
