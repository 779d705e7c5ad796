// libFuzzer target for one mesh format (VRDEFORM_FUZZ_FORMAT, one target per format): the input is
// a file of that format, read as readSurface or readTetMesh reads it. A vrd::Error is the expected
// answer to bad input; any other exception, a crash, a sanitizer report, a leak, or a mesh that
// breaks the readers' promises (indices in range, finite coordinates, tets or triangles present)
// is a finding. TetGen's three files come in one input, cut at each "%%": .node, .ele, .face.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_support.h"
#include "io/tet_formats.h"
#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"

namespace {

using namespace vrd;
using fuzz::require;

constexpr std::string_view kFormat = VRDEFORM_FUZZ_FORMAT;

bool finite(const std::vector<Vec3>& vertices) {
  for (const Vec3& v : vertices)
    if (!isFinite(v)) return false;
  return true;
}

template <class Cells>
bool inRange(const Cells& cells, std::size_t vertexCount) {
  for (const auto& cell : cells)
    for (Index i : cell)
      if (i >= vertexCount) return false;
  return true;
}

void checkTets(const TetMesh& mesh, const std::vector<Triangle>& faces) {
  require(!mesh.tets.empty() && finite(mesh.vertices));
  require(inRange(mesh.tets, mesh.vertices.size()) && inRange(faces, mesh.vertices.size()));
}

TetMesh readTetGen(std::string_view input, std::vector<Triangle>& faces) {
  std::string_view parts[3];
  int n = 0;
  for (std::size_t cut; n < 2 && (cut = input.find("%%")) != std::string_view::npos; ++n) {
    parts[n] = input.substr(0, cut);
    input.remove_prefix(cut + 2);
  }
  parts[n] = input;
  const io::TetGenText node{parts[0], "fuzz.node"}, ele{parts[1], "fuzz.ele"}, face{parts[2], "fuzz.face"};
  return io::parseTetGen(node, ele, n == 2 ? &face : nullptr, &faces);
}

TetMesh readTets(std::string_view input, std::vector<Triangle>& faces) {
  if (kFormat == "tetgen") return readTetGen(input, faces);
  TetMesh mesh;
  const std::string name = "fuzz." + std::string(kFormat);
  if (kFormat == "medit") mesh = io::readMedit(input, name, &faces);
  if (kFormat == "gmsh") mesh = io::readGmsh(input, name, &faces);
  if (kFormat == "vtk") mesh = io::readVtkLegacy(input, name, &faces);
  if (kFormat == "vtu") mesh = io::readVtu(input, name, &faces);
  io::checkReadMesh(mesh, name);  // as readTetMesh does after each of these
  return mesh;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input = fuzz::text(data, size);
  constexpr bool surface = kFormat == "obj" || kFormat == "stl" || kFormat == "off" || kFormat == "ply";
  try {
    if (surface) {
      static const fuzz::ScratchFile file("." + std::string(kFormat));
      const TriMesh mesh = readSurface(file.write(input));
      require(!mesh.triangles.empty() && finite(mesh.vertices) && inRange(mesh.triangles, mesh.vertices.size()));
    } else {
      std::vector<Triangle> faces;
      checkTets(readTets(input, faces), faces);
    }
  } catch (const Error&) {
    // bad input, said so
  }
  return 0;
}
