#pragma once
// OFF (Geomview's Object File Format, ASCII) surface reader. Hand-written because Assimp 5.2's OFF
// importer allocates what the header's vertex count asks for before looking at the file: a
// 66-byte file claiming 10^9 vertices made it ask for 13 GB. Here every count is checked against
// what the rest of the file can hold before anything is reserved.

#include <string>
#include <string_view>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Vertices in file order and polygons (3 or more corners) fanned into triangles; faces of fewer
/// corners (points, lines) are dropped. The header keyword ([ST][C][N][4]OFF) is optional; per-vertex
/// normals, colours and texture coordinates and per-face colours are read past. Throws vrd::Error
/// "name:line: what". Indices are range-checked; coordinates are not (readSurface does).
TriMesh readOff(std::string_view text, const std::string& name);

}  // namespace vrd
