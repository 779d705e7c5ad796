#pragma once
// The readers and writers behind readTetMesh/writeTetMesh, one file per format. A reader gets the
// file's bytes and its name for messages; indices it returns are checked to be in range.

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/io/tet_io.h"

namespace vrd::io {

TetMesh readTetGen(const std::filesystem::path& nodePath, std::vector<Triangle>* faces);
/// One TetGen file's bytes and its name for messages.
struct TetGenText {
  std::string_view text;
  std::string name;
};
/// readTetGen on files already read; `face` may be null (no .face, or none wanted).
TetMesh parseTetGen(const TetGenText& node, const TetGenText& ele, const TetGenText* face,
                    std::vector<Triangle>* faces);
void writeTetGen(const std::filesystem::path& anyPath, const TetMesh& mesh);

TetMesh readMedit(std::string_view text, const std::string& name, std::vector<Triangle>* faces);
void writeMedit(std::ostream& out, const TetMesh& mesh);

TetMesh readGmsh(std::string_view text, const std::string& name, std::vector<Triangle>* faces);
void writeGmsh(std::ostream& out, const TetMesh& mesh, GmshVersion version);

/// VTK's cell type ids (both VTK formats): the cells the readers keep, and the higher-order tets
/// they refuse by name.
constexpr std::int64_t kVtkTriangle = 5, kVtkTet = 10, kVtkQuadraticTet = 24, kVtkLagrangeTet = 71;

TetMesh readVtkLegacy(std::string_view text, const std::string& name, std::vector<Triangle>* faces);
void writeVtkLegacy(std::ostream& out, const TetMesh& mesh);

TetMesh readVtu(std::string_view text, const std::string& name, std::vector<Triangle>* faces);
/// A named 3-vector per point, written as <PointData>.
struct VtuPointArray {
  std::string_view name;
  std::span<const Vec3> values;
};
/// Writes the points with `cells` as VTK tetrahedra (N = 4) or triangles (N = 3).
template <std::size_t N>
void writeVtu(std::ostream& out, std::span<const Vec3> points, std::span<const std::array<Index, N>> cells,
              std::span<const VtuPointArray> pointData, const TetWriteOptions& options);

/// Checks what every reader promises: tets present, finite coordinates, at most 2^32 - 1 vertices.
void checkReadMesh(const TetMesh& mesh, const std::string& name);
/// Checks that the mesh can be written and read back: tets present, indices in range, finite coordinates.
void checkWritableMesh(const TetMesh& mesh);

}  // namespace vrd::io
