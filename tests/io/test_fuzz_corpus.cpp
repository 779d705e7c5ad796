// The mesh fuzz targets' corpora (tests/fuzz_corpus/<format>, fuzz/mesh_fuzz.cpp) through the public
// readers: the seeds read, and the inputs the fuzzers found (bad_*) are refused with a vrd::Error.
// Some findings were undefined behaviour (ply/ok_vertex_list_out_of_int_range, bad_nan_list_count),
// which the asan preset's UndefinedBehaviorSanitizer sees here.
#include <gtest/gtest.h>

#include <string>
#include <string_view>
#include <vector>

#include "fuzz_corpus.h"
#include "test_support.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tet_io.h"

namespace vrd {
namespace {

using testing::writeBytes;

void checkSurfaces(const std::string& format) {
  const testing::TempDir dir;
  testing::checkCorpus(format, [&](std::string_view bytes) {
    const std::filesystem::path path = dir / ("mesh." + format);
    writeBytes(path, bytes);
    readSurface(path);
  });
}

void checkTets(const std::string& format, const std::string& extension) {
  const testing::TempDir dir;
  testing::checkCorpus(format, [&](std::string_view bytes) {
    const std::filesystem::path path = dir / ("mesh." + extension);
    writeBytes(path, bytes);
    std::vector<Triangle> faces;
    readTetMesh(path, &faces);
  });
}

TEST(FuzzCorpus, Obj) { checkSurfaces("obj"); }
TEST(FuzzCorpus, Stl) { checkSurfaces("stl"); }
TEST(FuzzCorpus, Off) { checkSurfaces("off"); }
TEST(FuzzCorpus, Ply) { checkSurfaces("ply"); }

// Assimp's OFF importer asked for 13 GB for a header claiming 1111111111 vertices; our reader checks
// every count against the bytes left before reserving anything.
TEST(FuzzCorpus, OffCountsBeyondTheFileAreRefusedFirst) {
  const testing::TempDir dir;
  for (const char* name :
       {"bad_vertex_count_beyond_the_file", "bad_face_count_beyond_the_file", "bad_corner_count_beyond_the_file"}) {
    std::ifstream in(std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / "fuzz_corpus" / "off" / name, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    ASSERT_FALSE(bytes.empty()) << name;
    writeBytes(dir / "mesh.off", bytes);
    EXPECT_NE(testing::errorOf([&] { readSurface(dir / "mesh.off"); }).find("1111111111, but the"), std::string::npos)
        << name;
  }
}
TEST(FuzzCorpus, Gmsh) { checkTets("gmsh", "msh"); }
TEST(FuzzCorpus, Medit) { checkTets("medit", "mesh"); }
TEST(FuzzCorpus, VtkLegacy) { checkTets("vtk", "vtk"); }
TEST(FuzzCorpus, Vtu) { checkTets("vtu", "vtu"); }

// One input holds the three files, cut at each "%%": .node, .ele and (when there) .face.
TEST(FuzzCorpus, TetGen) {
  const testing::TempDir dir;
  testing::checkCorpus("tetgen", [&](std::string_view bytes) {
    const char* extensions[] = {".node", ".ele", ".face"};
    for (const char* e : extensions) std::filesystem::remove(dir / ("mesh" + std::string(e)));
    for (int part = 0; part < 3; ++part) {
      const std::size_t cut = part < 2 ? bytes.find("%%") : std::string_view::npos;
      writeBytes(dir / ("mesh" + std::string(extensions[part])), bytes.substr(0, cut));
      if (cut == std::string_view::npos) break;
      bytes.remove_prefix(cut + 2);
    }
    std::vector<Triangle> faces;
    readTetMesh(dir / "mesh.node", &faces);
  });
}

}  // namespace
}  // namespace vrd
