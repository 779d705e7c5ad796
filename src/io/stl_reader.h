#pragma once
// STL surface reader, binary and ASCII. Hand-written, like the OBJ, OFF and PLY readers, so that
// surfaces need no Assimp: a binary file's triangle count is checked against its size before
// anything is reserved, and ASCII errors name their line.

#include <string>
#include <string_view>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// Every facet's corners as three vertices of their own (readSurface welds them). Binary: an 80-byte
/// header, a little-endian uint32 count, 50 bytes a facet; a file of exactly that size is binary
/// even when its header starts with "solid". ASCII: one or more `solid ... endsolid` blocks of
/// `facet normal n n n / outer loop / vertex x y z ... / endloop / endfacet` (a loop of more than 3
/// vertices is fanned). Normals and attribute bytes are ignored. Throws vrd::Error.
TriMesh readStl(std::string_view bytes, const std::string& name);

}  // namespace vrd
