#pragma once
// Tetrahedral mesh files: TetGen (.node/.ele/.face), MEDIT (.mesh), Gmsh (.msh), VTK legacy (.vtk)
// and VTK XML (.vtu). The format follows from the file name's extension (any letter case).

#include <filesystem>
#include <vector>

#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

/// How a .vtu stores its arrays. ParaView writes AppendedRaw by default.
enum class VtuEncoding {
  AppendedRaw,     ///< binary after the XML in <AppendedData encoding="raw">
  AppendedBase64,  ///< the same, base64 encoded
  InlineBase64,    ///< base64 inside each DataArray (format="binary")
  Ascii,           ///< numbers as text
};

enum class GmshVersion { V2_2, V4_1 };

struct TetWriteOptions {
  VtuEncoding vtuEncoding = VtuEncoding::AppendedRaw;
  /// zlib-compresses the binary .vtu encodings (vtkZLibDataCompressor); ignored for Ascii.
  bool vtuCompress = false;
  GmshVersion gmshVersion = GmshVersion::V4_1;
};

/// Reads a tet mesh: .node or .ele (X.node + X.ele, and X.face when `faces` is wanted and it exists;
/// 0- or 1-based as the first node number says), .mesh (MEDIT, ASCII), .msh (Gmsh 2.x and 4.x ASCII),
/// .vtk (legacy UNSTRUCTURED_GRID, ASCII or BINARY, versions up to 5.1), .vtu (VTK XML: ascii,
/// base64 or appended raw/base64 arrays, optionally zlib-compressed; little-endian only).
/// Only tets are kept; `faces` (optional) receives the triangles the file lists (.face, MEDIT
/// Triangles, Gmsh and VTK triangle cells) as indices into the returned vertices. Other element types
/// are skipped; second-order tets are an error. Vertices are kept as numbered, used by a tet or not.
/// Throws vrd::Error naming the file (and line, for text) for anything malformed: truncated data,
/// garbage, wrong counts, out-of-range or non-integer indices, non-finite coordinates, no tets.
/// Counts in headers are checked against the bytes present before anything is allocated (compressed
/// .vtu data may claim at most zlib's maximum ratio, about 1032:1).
TetMesh readTetMesh(const std::filesystem::path& path, std::vector<Triangle>* faces = nullptr);

/// Throws vrd::Error unless writeTetMesh knows `path`'s extension: refuses an output before the
/// work that makes it.
void checkTetMeshOutput(const std::filesystem::path& path);

/// Writes a tet mesh, by extension: .node or .ele (X.node, X.ele and X.face with boundaryFaces(),
/// 1-based), .mesh, .msh (Gmsh 4.1 or 2.2 ASCII), .vtk (legacy ASCII), .vtu. Coordinates are written
/// so that reading them back gives the same floats. Every file appears complete or not at all.
/// Throws vrd::Error for an unknown extension, a mesh without tets, an out-of-range index, a
/// non-finite coordinate, or a file that cannot be written.
void writeTetMesh(const std::filesystem::path& path, const TetMesh& mesh, const TetWriteOptions& options = {});

}  // namespace vrd
