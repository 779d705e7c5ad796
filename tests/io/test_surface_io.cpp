// Surface formats: every format round-trips, every shared mesh loads, broken files are errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/mesh/primitives.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;
using testing::kMeshes;

class SurfaceIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("vrd_surface_io_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path file(const std::string& name) const { return dir_ / name; }
  fs::path writeBytes(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }
  fs::path dir_;
};

// A closed octahedron, vertices numbered in order of first use (the reader's numbering).
TriMesh octahedron() {
  TriMesh m;
  m.vertices = {{0, 0, 1.25f}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0.1f, 0.2f, -0.3f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}, {5, 2, 1}, {5, 3, 2}, {5, 4, 3}, {5, 1, 4}};
  return m;
}

using testing::readBytes;

void expectSameMesh(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t v = 0; v < a.vertices.size(); ++v) EXPECT_EQ(a.vertices[v], b.vertices[v]) << "vertex " << v;
  for (std::size_t t = 0; t < a.triangles.size(); ++t) EXPECT_EQ(a.triangles[t], b.triangles[t]) << "triangle " << t;
}

TEST_F(SurfaceIo, EveryFormatRoundTripsBitForBit) {
  const TriMesh mesh = octahedron();
  for (const char* ext : {".obj", ".off", ".stl", ".ply"})
    for (bool binary : {false, true}) {
      const fs::path path = file(std::string("octa") + (binary ? "_bin" : "_txt") + ext);
      writeSurface(path, mesh, {binary});
      SCOPED_TRACE(path.string());
      expectSameMesh(readSurface(path), mesh);
    }
}

TEST_F(SurfaceIo, BinaryAndAsciiStlAndPlyAreWhatTheyClaim) {
  writeSurface(file("a.stl"), octahedron(), {false});
  writeSurface(file("b.stl"), octahedron(), {true});
  writeSurface(file("b.ply"), octahedron(), {true});
  EXPECT_EQ(readBytes(file("a.stl")).rfind("solid", 0), 0u);
  EXPECT_EQ(readBytes(file("b.stl")).size(), 84u + 50u * 8);  // header + count + 8 facets of 50 bytes
  EXPECT_NE(readBytes(file("b.ply")).find("format binary_little_endian 1.0"), std::string::npos);
}

TEST_F(SurfaceIo, LargeGridRoundTripsThroughEveryFormat) {
  // Not in first-use order: compare triangle corners instead of indices.
  const TriMesh grid = makeGridCloth({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, 40, 30);
  for (const char* name : {"g.obj", "g.off", "g.stl", "g.ply"}) {
    writeSurface(file(name), grid);
    const TriMesh back = readSurface(file(name));
    ASSERT_EQ(back.vertices.size(), grid.vertices.size()) << name;
    ASSERT_EQ(back.triangles.size(), grid.triangles.size()) << name;
    for (std::size_t t = 0; t < grid.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(back.vertices[back.triangles[t][k]], grid.vertices[grid.triangles[t][k]]) << name << " face " << t;
  }
}

TEST_F(SurfaceIo, QuadsAreTriangulatedAndSeamsWelded) {
  // A cube of quads whose OBJ corners carry texture coordinates, so positions repeat with different attributes.
  std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvt 1 0\nvt 1 1\n";
  obj +=
      "f 1/1 4/2 3/3 2/1\nf 5/1 6/2 7/3 8/1\nf 1/2 2/3 6/1 5/2\nf 2/1 3/2 7/3 6/1\nf 3/3 4/1 8/2 7/2\nf 4/1 1/3 5/2 "
      "8/3\n";
  const TriMesh cube = readSurface(writeBytes("cube.obj", obj));
  EXPECT_EQ(cube.vertices.size(), 8u);
  EXPECT_EQ(cube.triangles.size(), 12u);
}

TEST_F(SurfaceIo, ObjReadsRelativeCornersContinuedLinesAndSkipsTheRest) {
  // A square of two triangles: negative corners, v/vt/vn forms, a continued face line, a vertex with a
  // colour, and keywords that carry no geometry.
  const std::string obj =
      "mtllib a.mtl\no square\nv 0 0 0\nv 1 0 0 0.5 0.5 0.5\nv 1 1 0\nvt 0 0\nvn 0 0 1\ng side\nusemtl red\n"
      "s off\nf 1/1/1 2//1 3/1\nv 0 1 0 # a comment\nl 1 2\np 3\nf -4 -2 \\\n -1\n";
  const TriMesh square = readSurface(writeBytes("square.obj", obj));
  ASSERT_EQ(square.vertices.size(), 4u);
  ASSERT_EQ(square.triangles.size(), 2u);
  EXPECT_EQ(square.vertices[square.triangles[1][2]], Vec3(0, 1, 0));  // -1: the last vertex above the face
}

TEST_F(SurfaceIo, ObjErrorsNameTheLine) {
  const std::string head = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::pair<std::string, std::string> cases[] = {
      {head + "f 1 2 4\n", "bad.obj:4: face corner 4 refers to a vertex not defined above it (3 so far)"},
      {head + "f 0 1 2\n", "bad.obj:4: face corner 0: OBJ numbers vertices from 1"},
      {head + "f 1 2\n", "bad.obj:4: a face needs at least 3 corners, found 2"},
      {"v 0 0\n", "bad.obj:1: a vertex needs 3 coordinates, found 2"},
      {"# big\nv 1e39 0 0\n", "bad.obj:2: vertex coordinate 1e39 is out of range for a float"},
      {"v 0 zero 0\n", "bad.obj:1: 'zero' is not a vertex coordinate"},
      {head + "f 1 2 x\n", "bad.obj:4: 'x' is not a face corner"},
      {head + "f -4 1 2\n", "bad.obj:4: face corner -4 refers to a vertex not defined above it"},
  };
  for (const auto& [text, says] : cases) {
    try {
      readSurface(writeBytes("bad.obj", text));
      ADD_FAILURE() << text << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
}

TEST_F(SurfaceIo, StlTellsBinaryFromAsciiByItsSize) {
  // A binary file whose header starts with "solid", as some exporters write them.
  writeSurface(file("b.stl"), octahedron(), {true});
  std::string bytes = readBytes(file("b.stl"));
  bytes.replace(0, 5, "solid");
  EXPECT_EQ(readSurface(writeBytes("solid_header.stl", bytes)).triangles.size(), 8u);
  // ASCII: two solids, a quad loop fanned, no final endsolid.
  const std::string ascii =
      "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n"
      "endloop\nendfacet\nendsolid a\nsolid b\nfacet normal 0 0 1\nouter loop\nvertex 0 0 1\nvertex 1 0 1\n"
      "vertex 1 1 1\nendloop\nendfacet\n";
  const TriMesh mesh = readSurface(writeBytes("two.stl", ascii));
  EXPECT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.vertices.size(), 7u);
}

TEST_F(SurfaceIo, StlErrorsSayWhatIsWrong) {
  writeSurface(file("b.stl"), octahedron(), {true});
  const std::string binary = readBytes(file("b.stl"));
  const std::pair<std::string, std::string> cases[] = {
      {binary.substr(0, binary.size() - 1), "a binary STL of 8 facets takes 484 bytes, the file has 483"},
      {"hello", "too short for a binary STL (84) and not ASCII STL"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
       "bad.stl:5: a facet needs at least 3 vertices, found 2"},
      {"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 -1e39 0\n",
       "bad.stl:6: vertex coordinate -1e39 is out of range for a float"},
      {"solid x\nfacet normal 0 0 1\nouter lop\n", "bad.stl:3: expected 'loop', found 'lop'"},
  };
  for (const auto& [text, says] : cases) {
    try {
      readSurface(writeBytes("bad.stl", text));
      ADD_FAILURE() << text << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
}

TEST_F(SurfaceIo, EverySharedMeshLoadsWithItsDocumentedCounts) {
  const std::pair<const char*, std::pair<std::size_t, std::size_t>> expected[] = {
      {"bear.obj", {13826, 27648}},
      {"bear_coarse.obj", {451, 898}},
      {"bunny.obj", {1839, 3674}},
      {"bunny_coarse.obj", {352, 700}},
      {"flag_plane.obj", {841, 1600}},
      {"jelly_blobby.obj", {2027, 4050}},
      {"jelly_blobby_coarse.obj", {296, 588}},
      {"liver.obj", {2557, 5110}},
      {"liver_coarse.obj", {343, 682}},
      {"sphere.obj", {812, 1620}},
      {"sphere_coarse.obj", {162, 320}}};
  for (const auto& [name, counts] : expected) {
    const TriMesh mesh = readSurface(kMeshes / name);
    EXPECT_EQ(mesh.vertices.size(), counts.first) << name;
    EXPECT_EQ(mesh.triangles.size(), counts.second) << name;
    EXPECT_NO_THROW(validateTriMesh(mesh)) << name;
  }
}

TEST_F(SurfaceIo, OriginalOffFilesLoadLikeTheirObjCopies) {
  // CGAL's originals, one a COFF with vertex colours; the OBJ copies keep their vertex order.
  const std::pair<const char*, const char*> pairs[] = {{"bear.off", "bear.obj"},
                                                       {"blobby.off", "jelly_blobby.obj"},
                                                       {"larger_sphere.off", "sphere.obj"},
                                                       {"plane.off", "flag_plane.obj"},
                                                       {"sphere.off", "sphere_coarse.obj"}};
  for (const auto& [off, obj] : pairs) {
    const TriMesh a = readSurface(kMeshes / "orig" / "cgal-5.5.1" / off), b = readSurface(kMeshes / obj);
    ASSERT_EQ(a.vertices.size(), b.vertices.size()) << off;
    ASSERT_EQ(a.triangles, b.triangles) << off;
    for (std::size_t v = 0; v < a.vertices.size(); ++v) ASSERT_LT((a.vertices[v] - b.vertices[v]).norm(), 1e-5f) << off;
  }
}

TEST_F(SurfaceIo, MissingEmptyAndGarbageFilesAreErrors) {
  auto expectError = [](const fs::path& path, const std::string& says) {
    try {
      readSurface(path);
      ADD_FAILURE() << path << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  expectError(file("nothing.obj"), "no such file");
  expectError(writeBytes("empty.stl", ""), "empty");
  expectError(writeBytes("words.obj", "hello world\nthis is not a mesh\n"), "");
  expectError(writeBytes("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "non-finite");
  expectError(writeBytes("inf.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n"),
              "inf.off:4: vertex coordinate 1e39 is out of range");
  expectError(writeBytes("points.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "");
  expectError(writeBytes("bad.xyz", "v 0 0 0\n"), "");

  std::mt19937 random(7);
  for (const char* ext : {".obj", ".off", ".stl", ".ply"})
    for (std::size_t size : {1u, 84u, 200u, 5000u}) {
      std::string bytes(size, '\0');
      for (char& c : bytes) c = static_cast<char>(random());
      expectError(writeBytes(std::string("random") + std::to_string(size) + ext, bytes), "");
    }
}

TEST_F(SurfaceIo, EveryTruncationIsAnErrorOrAPartialMesh) {
  const TriMesh mesh = octahedron();
  for (const char* ext : {".obj", ".off", ".stl", ".ply"})
    for (bool binary : {false, true}) {
      const fs::path whole = file(std::string("whole") + (binary ? "_b" : "_a") + ext);
      writeSurface(whole, mesh, {binary});
      const std::string bytes = readBytes(whole);
      for (std::size_t n = 0; n < bytes.size(); n += n < 100 ? 1 : 17) {
        const fs::path cut = writeBytes(std::string("cut") + ext, bytes.substr(0, n));
        try {
          const TriMesh part = readSurface(cut);
          // Text formats may end cleanly at a line break; what was read must be sound.
          EXPECT_LE(part.triangles.size(), mesh.triangles.size());
          for (const Triangle& t : part.triangles)
            for (Index v : t) EXPECT_LT(v, part.vertices.size());
        } catch (const Error&) {
        }
      }
    }
}

TEST_F(SurfaceIo, MutatedFilesAreErrorsOrSoundMeshes) {
  std::mt19937 random(11);
  const char noise[] = "0123456789-.e+ \nfv/#";
  for (const char* ext : {".obj", ".off", ".stl", ".ply"})
    for (bool binary : {false, true}) {
      const fs::path whole = file(std::string("whole") + (binary ? "_b" : "_a") + ext);
      writeSurface(whole, octahedron(), {binary});
      const std::string bytes = readBytes(whole);
      for (int trial = 0; trial < 30; ++trial) {
        std::string mutated = bytes;
        for (int k = 0; k < 1 + trial % 6; ++k) {
          char& c = mutated[random() % mutated.size()];
          c = trial % 2 ? static_cast<char>(random()) : noise[random() % (sizeof noise - 1)];
        }
        try {
          const TriMesh mesh = readSurface(writeBytes(std::string("mutated") + ext, mutated));
          for (const Triangle& t : mesh.triangles)
            for (Index v : t) ASSERT_LT(v, mesh.vertices.size());
          for (const Vec3& p : mesh.vertices) ASSERT_TRUE(isFinite(p));
        } catch (const Error&) {
        }
      }
    }
}

TEST_F(SurfaceIo, WritingLeavesNoHalfWrittenFile) {
  EXPECT_THROW(writeSurface(dir_ / "missing" / "x.obj", octahedron()), Error);
  EXPECT_FALSE(fs::exists(dir_ / "missing"));
  EXPECT_THROW(writeSurface(file("x.dae"), octahedron()), Error);
  TriMesh broken = octahedron();
  broken.triangles[3][1] = 99;
  EXPECT_THROW(writeSurface(file("broken.obj"), broken), Error);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace vrd
