// Tet mesh files: every writer round-trips bit for bit, the shared real meshes read with the right
// counts and a closed boundary, hand-written files of each format read as intended, and malformed
// input of any kind ends in vrd::Error, never a crash (the CI runs this under AddressSanitizer).

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "test_support.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/io/tet_io.h"
#include "vrdeform/io/vtu_sequence.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/primitives.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;
const fs::path kTetMeshes = testing::kMeshes / "tet";

using testing::readBytes;
using testing::writeBytes;

using testing::errorOf;

#define EXPECT_ERROR_MENTIONS(statement, text)                                    \
  do {                                                                            \
    const std::string message_ = errorOf([&] { statement; });                     \
    EXPECT_NE(message_.find(text), std::string::npos) << "message: " << message_; \
  } while (false)

void expectSameMesh(const TetMesh& expected, const TetMesh& actual) {
  ASSERT_EQ(expected.vertices.size(), actual.vertices.size());
  for (std::size_t v = 0; v < expected.vertices.size(); ++v)
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(expected.vertices[v][c]),
                std::bit_cast<std::uint32_t>(actual.vertices[v][c]))
          << "vertex " << v << " coordinate " << c << ": " << expected.vertices[v][c] << " vs "
          << actual.vertices[v][c];
  EXPECT_EQ(expected.tets, actual.tets);
}

// A box with coordinates that use every bit of the mantissa, plus unused vertices with extreme values.
TetMesh testMesh() {
  TetMesh mesh = makeBoxTets(Vec3(0.1f, -0.3f, 0.7f), Vec3(0.37f, 1.1f, 0.213f), 3, 2, 2);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> jitter(-0.01f, 0.01f);
  for (Vec3& v : mesh.vertices) v += Vec3(jitter(random), jitter(random), jitter(random));
  mesh.vertices.push_back(Vec3(-0.0f, std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max()));
  mesh.vertices.push_back(Vec3(std::numeric_limits<float>::lowest(), 1e-30f, 123456789.0f));
  mesh.vertices.push_back(
      Vec3(std::nextafter(1.0f, 2.0f), std::nextafter(1.0f, 0.0f), -std::numeric_limits<float>::min()));
  return mesh;
}

struct Variant {
  std::string file;
  TetWriteOptions options;
};

std::vector<Variant> allVariants() {
  std::vector<Variant> v = {{"m.node", {}}, {"m.mesh", {}}, {"m41.msh", {}}, {"m.vtk", {}}};
  TetWriteOptions gmsh22;
  gmsh22.gmshVersion = GmshVersion::V2_2;
  v.push_back({"m22.msh", gmsh22});
  const std::pair<VtuEncoding, const char*> encodings[] = {{VtuEncoding::AppendedRaw, "raw"},
                                                           {VtuEncoding::AppendedBase64, "appended64"},
                                                           {VtuEncoding::InlineBase64, "inline64"},
                                                           {VtuEncoding::Ascii, "ascii"}};
  for (const auto& [encoding, name] : encodings)
    for (bool compress : {false, true}) {
      if (encoding == VtuEncoding::Ascii && compress) continue;
      TetWriteOptions o;
      o.vtuEncoding = encoding;
      o.vtuCompress = compress;
      v.push_back({std::string(name) + (compress ? "_z" : "") + ".vtu", o});
    }
  return v;
}

// What every successful read promises.
void expectValidLooking(const TetMesh& mesh, const std::vector<Triangle>& faces) {
  ASSERT_FALSE(mesh.tets.empty());
  for (const Vec3& v : mesh.vertices) ASSERT_TRUE(isFinite(v));
  for (const Tet& t : mesh.tets)
    for (Index i : t) ASSERT_LT(i, mesh.vertices.size());
  for (const Triangle& t : faces)
    for (Index i : t) ASSERT_LT(i, mesh.vertices.size());
}

// Reads `path`; it must throw vrd::Error or give a valid-looking mesh. False when it threw.
bool readsOrThrows(const fs::path& path) {
  std::vector<Triangle> faces;
  try {
    const TetMesh mesh = readTetMesh(path, &faces);
    expectValidLooking(mesh, faces);
    return true;
  } catch (const Error&) {
    return false;
  }
}

double tetVolume(const TetMesh& mesh, const Tet& t) {
  return signedTetVolume(mesh.vertices[t[0]].cast<double>().eval(), mesh.vertices[t[1]].cast<double>().eval(),
                         mesh.vertices[t[2]].cast<double>().eval(), mesh.vertices[t[3]].cast<double>().eval());
}

// Every edge in exactly two faces, once in each direction (closed and consistently oriented), and the
// volume the faces enclose equals the tets' total (inverted tets counted as positive: their faces are
// flipped to point outward).
void expectClosedBoundary(const TetMesh& mesh, const std::vector<Triangle>& faces) {
  std::map<std::pair<Index, Index>, int> directed;
  for (const Triangle& f : faces)
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  for (const auto& [edge, n] : directed) {
    ASSERT_EQ(n, 1) << "edge " << edge.first << "-" << edge.second << " twice in the same direction";
    ASSERT_EQ(directed.count({edge.second, edge.first}), 1u) << "edge " << edge.first << "-" << edge.second << " open";
  }
  double enclosed = 0, total = 0;
  for (const Triangle& f : faces) {
    const Vec3T<double> a = mesh.vertices[f[0]].cast<double>(), b = mesh.vertices[f[1]].cast<double>(),
                        c = mesh.vertices[f[2]].cast<double>();
    enclosed += a.dot(b.cross(c)) / 6;
  }
  for (const Tet& t : mesh.tets) total += std::abs(tetVolume(mesh, t));
  EXPECT_NEAR(enclosed, total, 1e-9 * std::abs(total));
}

// ---- round trips

TEST(TetIo, EveryFormatRoundTripsExactly) {
  TempDir dir;
  const TetMesh mesh = testMesh();
  for (const Variant& v : allVariants()) {
    SCOPED_TRACE(v.file);
    writeTetMesh(dir / v.file, mesh, v.options);
    expectSameMesh(mesh, readTetMesh(dir / v.file));
  }
  // Nothing but the files asked for: no temporaries left behind.
  std::vector<std::string> expected = {"m.ele", "m.face", "m.node"};
  for (const Variant& v : allVariants())
    if (v.file != "m.node") expected.push_back(v.file);
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.files(), expected);
}

TEST(TetIo, NodeWritesOutwardBoundaryFacesAndReadsThemBack) {
  TempDir dir;
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3(1, 2, 3), 2, 3, 1);
  writeTetMesh(dir / "box.NODE", mesh);  // the extension in any case
  std::vector<Triangle> faces;
  expectSameMesh(mesh, readTetMesh(dir / "box.ele", &faces));
  EXPECT_EQ(faces, boundaryFaces(mesh));
  EXPECT_EQ(faces.size(), 2u * 2 * (2 * 3 + 3 * 1 + 1 * 2));
  expectClosedBoundary(mesh, faces);
}

TEST(TetIo, ReadsZeroBasedTetGenFiles) {
  TempDir dir;
  writeBytes(dir / "t.node",
             "# a comment\n5 3 1 1\n0 0 0 0 7.5 1\n1 1 0 0 0 1\n2 0 1 0 0 1 # trailing\n"
             "3 0 0 1 0 0\n4 1 1 1 0 0\n");
  writeBytes(dir / "t.ele", "2 4 1\n0 0 1 2 3 5\n1 1 2 3 4 5\n");
  writeBytes(dir / "t.face", "1 1\n0 0 2 1 -1\n");
  std::vector<Triangle> faces;
  const TetMesh mesh = readTetMesh(dir / "t.node", &faces);
  ASSERT_EQ(mesh.vertices.size(), 5u);
  EXPECT_EQ(mesh.vertices[4], Vec3(1, 1, 1));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}}));
}

// ---- the shared real meshes

void checkRealMesh(const fs::path& path, std::size_t points, std::size_t tets, std::size_t boundary) {
  SCOPED_TRACE(path.string());
  const TetMesh mesh = readTetMesh(path);
  EXPECT_EQ(mesh.vertices.size(), points);
  EXPECT_EQ(mesh.tets.size(), tets);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) ASSERT_GT(tetVolume(mesh, mesh.tets[t]), 0) << "tet " << t;
  EXPECT_NO_THROW(validateTetMesh(mesh));
  const std::vector<Triangle> faces = boundaryFaces(mesh);
  if (boundary) {
    EXPECT_EQ(faces.size(), boundary);
  }
  expectClosedBoundary(mesh, faces);
}

TEST(TetIo, ReadsTheSharedMeshes) {
  checkRealMesh(kTetMeshes / "unit_ball.mesh", 363, 1110, 602);
  checkRealMesh(kTetMeshes / "cube_medium_tetra.mesh", 448, 1782, 0);
  checkRealMesh(kTetMeshes / "octahedron.node", 330, 1224, 0);
  checkRealMesh(kTetMeshes / "octahedron.ele", 330, 1224, 0);
}

TEST(TetIo, SharedMeshesRoundTripThroughEveryFormat) {
  TempDir dir;
  const TetMesh mesh = readTetMesh(kTetMeshes / "unit_ball.mesh");
  for (const Variant& v : allVariants()) {
    SCOPED_TRACE(v.file);
    writeTetMesh(dir / v.file, mesh, v.options);
    expectSameMesh(mesh, readTetMesh(dir / v.file));
  }
}

// ---- hand-written files

// Two tets (0,1,2,3) and (1,2,3,4) sharing a face, and the triangle (0,2,1).
const TetMesh kTwoTets{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)},
                       {{0, 1, 2, 3}, {1, 2, 3, 4}}};

// BINARY: big-endian numbers right after the line that announces them.
std::string binaryVtk() {
  std::string bin = "# vtk DataFile Version 4.2\nbinary\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 float\n";
  const auto big32 = [&](std::uint32_t u) {
    for (int s = 24; s >= 0; s -= 8) bin += static_cast<char>((u >> s) & 0xff);
  };
  for (const Vec3& p : kTwoTets.vertices)
    for (int c = 0; c < 3; ++c) big32(std::bit_cast<std::uint32_t>(p[c]));
  bin += "\nCELLS 2 10\n";
  for (const Tet& t : kTwoTets.tets) {
    big32(4);
    for (Index i : t) big32(i);
  }
  bin += "\nCELL_TYPES 2\n";
  big32(10);
  big32(10);
  return bin + "\n";
}

TEST(TetIo, ReadsGmsh41WithEntityBlocksAndSparseTags) {
  TempDir dir;
  writeBytes(dir / "g.msh",
             "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
             "$PhysicalNames\n1\n3 1 \"the $Nodes body\"\n$EndPhysicalNames\n"
             "$Entities\n0 0 1 1\n1 0 0 0 1 1 0 0 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
             "$Nodes\n2 5 7 100\n"
             "2 1 1 3\n10\n20\n30\n0 0 0 0.5 0.5\n1 0 0 1 0\n0 1 0 0 1\n"  // parametric surface block: u v follow
             "3 1 0 2\n7\n100\n0 0 1\n1 1 1\n"
             "$EndNodes\n"
             "$Elements\n3 4 1 40\n"
             "1 1 1 1\n5 10 20\n"     // a line: skipped
             "2 1 2 1\n9 10 30 20\n"  // a triangle
             "3 1 4 2\n40 10 20 30 7\n31 20 30 7 100\n"
             "$EndElements\n$Comments\nanything at all\n$EndComments\n");
  std::vector<Triangle> faces;
  expectSameMesh(kTwoTets, readTetMesh(dir / "g.msh", &faces));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}}));
}

TEST(TetIo, ReadsGmsh22AndGmsh40) {
  TempDir dir;
  writeBytes(dir / "g22.msh",
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n"
             "3 0 0 0\n5 1 0 0\n8 0 1 0\n13 0 0 1\n21 1 1 1\n$EndNodes\n"
             "$Elements\n5\n1 15 2 0 1 3\n2 1 2 0 1 3 5\n3 2 2 0 1 3 8 5\n"
             "4 4 3 1 1 0 3 5 8 13\n5 4 2 0 1 5 8 13 21\n$EndElements\n");
  std::vector<Triangle> faces;
  expectSameMesh(kTwoTets, readTetMesh(dir / "g22.msh", &faces));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}}));

  writeBytes(dir / "g40.msh",
             "$MeshFormat\n4 0 8\n$EndMeshFormat\n$Nodes\n2 5\n"
             "1 2 0 3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
             "1 3 0 2\n4 0 0 1\n5 1 1 1\n$EndNodes\n"
             "$Elements\n1 2\n1 3 4 2\n1 1 2 3 4\n2 2 3 4 5\n$EndElements\n");
  expectSameMesh(kTwoTets, readTetMesh(dir / "g40.msh"));
}

TEST(TetIo, ReadsVtkLegacyAsciiBinaryAnd51) {
  TempDir dir;
  writeBytes(dir / "a.vtk",
             "# vtk DataFile Version 3.0\ntwo tets\nASCII\n\nDATASET UNSTRUCTURED_GRID\n"
             "FIELD FieldData 1\nTIME 1 1 double\n2.5\n"
             "POINTS 5 double\n0 0 0  1 0 0  0 1 0\n0 0 1  1 1 1\n"
             "CELLS 4 16\n1 4\n3 0 2 1\n4 0 1 2 3\n4 1 2 3 4\n"
             "CELL_TYPES 4\n1 5 10 10\n"
             "POINT_DATA 5\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3 4 5\n");
  std::vector<Triangle> faces;
  expectSameMesh(kTwoTets, readTetMesh(dir / "a.vtk", &faces));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}}));

  writeBytes(dir / "v51.vtk",
             "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET UNSTRUCTURED_GRID\n"
             "POINTS 5 float\n0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n"
             "METADATA\nINFORMATION 0\n\n"
             "CELLS 3 8\nOFFSETS vtktypeint64\n0 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 3 4\n"
             "CELL_TYPES 2\n10\n10\n");
  expectSameMesh(kTwoTets, readTetMesh(dir / "v51.vtk"));

  writeBytes(dir / "b.vtk", binaryVtk());
  expectSameMesh(kTwoTets, readTetMesh(dir / "b.vtk"));
}

void appendLittle(std::string& out, std::uint64_t value, int bytes) {
  for (int k = 0; k < bytes; ++k) out += static_cast<char>((value >> (8 * k)) & 0xff);
}
std::string littleDoubles(const TetMesh& mesh) {
  std::string s;
  for (const Vec3& p : mesh.vertices)
    for (int c = 0; c < 3; ++c) appendLittle(s, std::bit_cast<std::uint64_t>(static_cast<double>(p[c])), 8);
  return s;
}
std::string base64(std::string_view bytes) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = 0;
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? abc[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// ParaView's default: UInt64 headers, appended raw data, Float64 points, point and cell data to skip,
// and a triangle among the cells.
std::string paraviewStyleVtu() {
  std::string data;
  const auto array = [&](const std::string& bytes) {
    const std::size_t offset = data.size();
    appendLittle(data, bytes.size(), 8);
    data += bytes;
    return std::to_string(offset);
  };
  std::string pressure, conn, offsets, types, ids;
  for (int i = 0; i < 5; ++i) appendLittle(pressure, std::bit_cast<std::uint32_t>(1.5f * i), 4);
  const std::string pressureAt = array(pressure);
  const std::string pointsAt = array(littleDoubles(kTwoTets));
  for (Index i : {0u, 2u, 1u, 0u, 1u, 2u, 3u, 1u, 2u, 3u, 4u}) appendLittle(conn, i, 8);
  const std::string connAt = array(conn);
  for (int o : {3, 7, 11}) appendLittle(offsets, static_cast<std::uint64_t>(o), 8);
  const std::string offsetsAt = array(offsets);
  for (int t : {5, 10, 10}) appendLittle(types, static_cast<std::uint64_t>(t), 1);
  const std::string typesAt = array(types);
  for (int c = 0; c < 3; ++c) appendLittle(ids, static_cast<std::uint64_t>(c), 4);
  const std::string idsAt = array(ids);
  return "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
         "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"5\" NumberOfCells=\"3\">\n"
         "      <PointData Scalars=\"p\">\n"
         "        <DataArray type=\"Float32\" Name=\"p\" format=\"appended\" RangeMin=\"0\" RangeMax=\"6\" offset=\"" +
         pressureAt +
         "\"/>\n      </PointData>\n"
         "      <CellData>\n        <DataArray type=\"Int32\" Name=\"id\" format=\"appended\" offset=\"" +
         idsAt +
         "\"/>\n      </CellData>\n"
         "      <Points>\n        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
         "format=\"appended\" offset=\"" +
         pointsAt +
         "\">\n          <InformationKey name=\"L2_NORM_RANGE\" location=\"vtkDataArray\" length=\"2\">\n"
         "            <Value index=\"0\">0</Value>\n          </InformationKey>\n        </DataArray>\n"
         "      </Points>\n      <Cells>\n"
         "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"" +
         connAt + "\"/>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" + offsetsAt +
         "\"/>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"" + typesAt +
         "\"/>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
         "  <AppendedData encoding=\"raw\">\n   _" +
         data + "\n  </AppendedData>\n</VTKFile>\n";
}

TEST(TetIo, ReadsParaViewStyleAppendedRawVtu) {
  TempDir dir;
  writeBytes(dir / "pv.vtu", paraviewStyleVtu());
  std::vector<Triangle> faces;
  expectSameMesh(kTwoTets, readTetMesh(dir / "pv.vtu", &faces));
  EXPECT_EQ(faces, (std::vector<Triangle>{{0, 2, 1}}));
}

// zlib blocks of `blockSize` bytes with a UInt32 header, header and blocks base64-encoded apart as
// VTK does. `corrupt` spoils the second block.
std::string compressedArray(const std::string& bytes, std::size_t blockSize, bool corrupt = false) {
  std::string header, blocks;
  const std::size_t count = (bytes.size() + blockSize - 1) / blockSize;
  appendLittle(header, count, 4);
  appendLittle(header, blockSize, 4);
  appendLittle(header, bytes.size() % blockSize, 4);
  for (std::size_t b = 0; b < count; ++b) {
    const std::size_t size = std::min(blockSize, bytes.size() - b * blockSize);
    uLongf length = compressBound(size);
    std::string block(length, '\0');
    EXPECT_EQ(compress(reinterpret_cast<Bytef*>(block.data()), &length,
                       reinterpret_cast<const Bytef*>(bytes.data() + b * blockSize), size),
              Z_OK);
    block.resize(length);
    if (corrupt && b == 1) block[length / 2] = static_cast<char>(block[length / 2] ^ 0x5a);
    appendLittle(header, length, 4);
    blocks += block;
  }
  return base64(header) + base64(blocks);
}

std::string compressedVtu(bool corrupt = false) {
  std::string points, conn, offsets, types;
  for (const Vec3& p : kTwoTets.vertices)
    for (int c = 0; c < 3; ++c) appendLittle(points, std::bit_cast<std::uint32_t>(p[c]), 4);
  for (const Tet& t : kTwoTets.tets)
    for (Index i : t) appendLittle(conn, i, 4);
  appendLittle(offsets, 4, 4);
  appendLittle(offsets, 8, 4);
  types = std::string("\x0a\x0a", 2);
  return "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\" "
         "compressor=\"vtkZLibDataCompressor\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"5\" NumberOfCells=\"2\">\n"
         "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"binary\">\n" +
         compressedArray(points, 16, corrupt) +
         "\n</DataArray>\n</Points>\n<Cells>\n"
         "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"binary\">" +
         compressedArray(conn, 32768) + "</DataArray>\n<DataArray type=\"UInt32\" Name=\"offsets\" format=\"binary\">" +
         compressedArray(offsets, 32768) + "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"binary\">" +
         compressedArray(types, 32768) + "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

TEST(TetIo, ReadsZlibCompressedBinaryVtu) {
  TempDir dir;
  writeBytes(dir / "z.vtu", compressedVtu());
  expectSameMesh(kTwoTets, readTetMesh(dir / "z.vtu"));
}

// ---- malformed input

// Small valid files of every format and variant.
std::vector<std::pair<std::string, std::string>> smallValidFiles(const TempDir& dir) {
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3(1, 1, 1), 1, 1, 1);
  std::vector<std::pair<std::string, std::string>> files;
  for (const Variant& v : allVariants()) {
    writeTetMesh(dir / v.file, mesh, v.options);
    files.emplace_back(v.file, readBytes(dir / v.file));
  }
  files.emplace_back("m.ele", readBytes(dir / "m.ele"));
  files.emplace_back("b.vtk", binaryVtk());
  files.emplace_back("pv.vtu", paraviewStyleVtu());
  files.emplace_back("z.vtu", compressedVtu());
  return files;
}

// For .node/.ele, writes the broken text under `name` and a valid partner file beside it.
fs::path writeBroken(const TempDir& dir, const std::string& name, std::string_view bytes,
                     const std::vector<std::pair<std::string, std::string>>& valid) {
  const fs::path path = dir / ("broken_" + name);
  writeBytes(path, bytes);
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".node" || ext == ".ele") {
    const std::string partner = ext == ".node" ? "m.ele" : "m.node";
    for (const auto& [n, text] : valid)
      if (n == partner) writeBytes(dir / ("broken_" + partner), text);
  }
  return path;
}

TEST(TetIo, EmptyFilesAreErrors) {
  TempDir dir;
  for (const char* name : {"e.node", "e.mesh", "e.msh", "e.vtk", "e.vtu"}) {
    writeBytes(dir / name, "");
    writeBytes(dir / "e.ele", "1 4 0\n1 1 2 3 4\n");
    EXPECT_ERROR_MENTIONS(readTetMesh(dir / name), "empty");
  }
}

TEST(TetIo, EveryTruncationIsAnErrorOrAValidMesh) {
  TempDir dir;
  const auto valid = smallValidFiles(dir);
  for (const auto& [name, text] : valid) {
    SCOPED_TRACE(name);
    // Every prefix of the small files; a few hundred spread over the larger ones, and always the last few.
    const std::size_t stride = text.size() / 300 + 1;
    int parsed = 0;
    for (std::size_t n = 0; n < text.size(); n += n + 32 >= text.size() ? 1 : stride)
      if (readsOrThrows(writeBroken(dir, name, std::string_view(text).substr(0, n), valid))) ++parsed;
    // Only cuts in the last few characters (digits of the last number, an End keyword) can still parse.
    EXPECT_LT(parsed, 40) << "prefixes of " << text.size() << " bytes";
    EXPECT_TRUE(readsOrThrows(writeBroken(dir, name, text, valid)));
  }
}

TEST(TetIo, RandomBytesAndMutationsAreErrorsOrValidMeshes) {
  TempDir dir;
  const auto valid = smallValidFiles(dir);
  std::mt19937 random(2024);
  std::uniform_int_distribution<int> byte(0, 255);
  for (const auto& [name, text] : valid) {
    SCOPED_TRACE(name);
    for (std::size_t size : {1, 3, 64, 1000, 5000}) {
      std::string noise(size, '\0');
      for (char& c : noise) c = static_cast<char>(byte(random));
      EXPECT_FALSE(readsOrThrows(writeBroken(dir, name, noise, valid)));
      // A valid start followed by noise.
      readsOrThrows(writeBroken(dir, name, text.substr(0, text.size() / 2) + noise, valid));
    }
    std::uniform_int_distribution<std::size_t> at(0, text.size() - 1);
    for (int m = 0; m < 100; ++m) {
      std::string mutated = text;
      for (int k = 0; k <= m % 3; ++k) mutated[at(random)] = static_cast<char>(byte(random));
      readsOrThrows(writeBroken(dir, name, mutated, valid));
    }
  }
}

TEST(TetIo, BrokenTextFilesNameTheProblem) {
  TempDir dir;
  const auto read = [&](const std::string& name, const std::string& text) {
    writeBytes(dir / name, text);
    return readTetMesh(dir / name);
  };
  const std::string medit = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";
  EXPECT_ERROR_MENTIONS(read("a.mesh", medit + "Tetrahedra\n1\n1 2 3 9 0\nEnd\n"),
                        "a.mesh:11: tetrahedron 1 refers to vertex 9");
  EXPECT_ERROR_MENTIONS(read("b.mesh", medit + "Tetrahedra\n1\n1 2 3.5 4 0\n"),
                        "expected a vertex number (an integer), found '3.5'");
  EXPECT_ERROR_MENTIONS(read("c.mesh", medit + "Tetrahedra\n2\n1 2 3 4 0\n0001 0002 0003 0004"),
                        "unexpected end of file, expected a reference number");
  EXPECT_ERROR_MENTIONS(read("d.mesh", medit + "Tetrahedra\n1000000000000\n1 2 3 4 0\n"), "can hold at most");
  EXPECT_ERROR_MENTIONS(read("e.mesh", "MeshVersionFormatted 2\nVertices\n1\nnan 0 0 0\n"), "non-finite");
  EXPECT_ERROR_MENTIONS(read("f.mesh", "MeshVersionFormatted 2\nVertices\n1\n1e39 0 0 0\n"), "out-of-range");
  EXPECT_ERROR_MENTIONS(read("g.mesh", medit + "Bogus\n"), "unknown MEDIT keyword 'Bogus'");
  EXPECT_ERROR_MENTIONS(read("h.mesh", medit + "End\n"), "no tetrahedra");
  EXPECT_ERROR_MENTIONS(read("i.mesh", medit + "TetrahedraP2\n"), "second-order tets are not supported");
  EXPECT_ERROR_MENTIONS(read("j.mesh", medit + "Tetrahedra\n1\n1 2 3 -4 0\n"), "refers to vertex -4");

  const std::string gmsh =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
  EXPECT_ERROR_MENTIONS(read("a.msh", gmsh + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 5\n$EndElements\n"),
                        "a.msh:19: tetrahedron 1 refers to node 5, which is not in $Nodes");
  EXPECT_ERROR_MENTIONS(read("b.msh", gmsh + "$Elements\n1 1 1 1\n3 1 11 1\n1 1 2 3 4 1 2 3 4 1 2\n$EndElements\n"),
                        "second-order tets are not supported");
  EXPECT_ERROR_MENTIONS(read("c.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 1000000000000 1 4\n"),
                        "can hold at most");
  EXPECT_ERROR_MENTIONS(read("d.msh", "$MeshFormat\n4.1 1 8\n"), "binary Gmsh files are not supported");
  EXPECT_ERROR_MENTIONS(read("e.msh", gmsh), "no tetrahedra");
  EXPECT_ERROR_MENTIONS(read("f.msh", gmsh + "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n"), "expected $EndElements");
  EXPECT_ERROR_MENTIONS(read("g.msh", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"), "version '3.0' is not supported");

  const std::string vtk =
      "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n";
  EXPECT_ERROR_MENTIONS(read("a.vtk", vtk + "CELLS 1 5\n4 0 1 2 4\nCELL_TYPES 1\n10\n"), "refers to point 4");
  EXPECT_ERROR_MENTIONS(read("b.vtk", vtk + "CELLS 1 11\n10 0 1 2 3 0 1 2 3 0 1\nCELL_TYPES 1\n24\n"),
                        "second-order tets are not supported");
  EXPECT_NO_THROW(read("c.vtk", vtk + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n"));
  EXPECT_ERROR_MENTIONS(read("d.vtk",
                             "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET UNSTRUCTURED_GRID\n"
                             "POINTS 1000000000 float\n\x01\x02"),
                        "only");
  EXPECT_ERROR_MENTIONS(read("e.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n"), "POLYDATA");
  EXPECT_ERROR_MENTIONS(read("f.vtk", vtk + "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n"), "cell types");
  EXPECT_ERROR_MENTIONS(read("g.vtk",
                             "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                             "POINTS 1 float\n0 inf 0\n"),
                        "non-finite");

  writeBytes(dir / "t.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "t.node"), "t.ele is missing");
  writeBytes(dir / "t.ele", "1 4 0\n1 1 2 3 99\n");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "t.node"), "t.ele:2: tetrahedron 1 refers to node 99");
  writeBytes(dir / "t.ele", "1 10 0\n1 1 2 3 4 1 2 3 4 1 2\n");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "t.node"), "second-order tets are not supported");
  writeBytes(dir / "u.node", "4 3 0 0\n1 0 0 0\n3 1 0 0\n3 0 1 0\n4 0 0 1\n");
  writeBytes(dir / "u.ele", "1 4 0\n1 1 2 3 4\n");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "u.node"), "u.node:3: node numbered 3, expected 2");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "nothing.node"), "no such file");
  EXPECT_ERROR_MENTIONS(readTetMesh(dir / "t.obj"), "unknown tet mesh format");
}

TEST(TetIo, BrokenVtuFilesNameTheProblem) {
  TempDir dir;
  const auto read = [&](const std::string& name, const std::string& text) {
    writeBytes(dir / name, text);
    return readTetMesh(dir / name);
  };
  std::string pv = paraviewStyleVtu();
  const auto replaced = [&](std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  EXPECT_ERROR_MENTIONS(read("a.vtu", replaced(pv, "LittleEndian", "BigEndian")), "big-endian");
  EXPECT_ERROR_MENTIONS(read("b.vtu", replaced(pv, "NumberOfPoints=\"5\"", "NumberOfPoints=\"100000000\"")),
                        "the header says 120 bytes, expected 2400000000");
  EXPECT_ERROR_MENTIONS(read("c.vtu", replaced(pv, "NumberOfPoints=\"5\"", "NumberOfPoints=\"-5\"")), "not a count");
  EXPECT_ERROR_MENTIONS(read("d.vtu", replaced(pv, "\"UInt8\" Name=\"types\"", "\"Float32\" Name=\"types\"")),
                        "not an integer type");
  EXPECT_ERROR_MENTIONS(read("e.vtu", pv.substr(0, pv.size() - 30)), "no </AppendedData>");
  EXPECT_ERROR_MENTIONS(read("f.vtu", replaced(pv, "<Points>", "<Points")), "XML error");
  EXPECT_ERROR_MENTIONS(read("h.vtu", replaced(pv, "\"UInt8\" Name=\"types\" format=\"appended\" offset=\"",
                                               "\"UInt8\" Name=\"types\" format=\"appended\" offset=\"9999")),
                        "not inside");

  const std::string ascii =
      "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" "
      "NumberOfCells=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" "
      "format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Cells>";
  const auto cells = [](const std::string& conn) {
    return "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">" + conn +
           "</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray>"
           "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells></Piece>"
           "</UnstructuredGrid></VTKFile>";
  };
  EXPECT_NO_THROW(read("i.vtu", ascii + cells("0 1 2 3")));
  EXPECT_ERROR_MENTIONS(read("j.vtu", ascii + cells("0 1 2 4")), "refers to point 4");
  EXPECT_ERROR_MENTIONS(read("k.vtu", ascii + cells("0 1 2 x")), "found 'x'");
  EXPECT_ERROR_MENTIONS(read("l.vtu", ascii + cells("0 1 2")), "connectivity");
  EXPECT_ERROR_MENTIONS(read("m.vtu", replaced(ascii, "0 0 0 1", "0 nan 0 1") + cells("0 1 2 3")), "non-finite");

  std::string z = compressedVtu();
  const std::size_t data = z.find("format=\"binary\">") + 16;
  EXPECT_ERROR_MENTIONS(read("n.vtu", z.substr(0, data) + "@@@@" + z.substr(data + 4)), "invalid base64 character");
  EXPECT_ERROR_MENTIONS(read("o.vtu", z.substr(0, data) + "A===" + z.substr(data + 4)), "misplaced '='");
  EXPECT_ERROR_MENTIONS(read("p.vtu", compressedVtu(true)), "does not inflate");
  // A compression header claiming 2^31 blocks of 2^31 bytes for five points.
  std::string header;
  for (std::uint64_t v : {0x7fffffffu, 0x7fffffffu, 0u}) appendLittle(header, v, 4);
  EXPECT_ERROR_MENTIONS(read("q.vtu", z.substr(0, data) + "\n" + base64(header) + "\n" + z.substr(z.find('<', data))),
                        "cannot");
}

TEST(TetIo, WritingIntoAMissingFolderFailsAndLeavesNothing) {
  TempDir dir;
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 1, 1, 1);
  for (const Variant& v : allVariants()) {
    SCOPED_TRACE(v.file);
    EXPECT_ERROR_MENTIONS(writeTetMesh(dir / "missing" / v.file, mesh, v.options), "cannot write");
  }
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_TRUE(dir.files().empty());

  TetMesh bad = mesh;
  bad.tets[2][1] = 99;
  EXPECT_ERROR_MENTIONS(writeTetMesh(dir / "bad.vtu", bad), "tet 3: it refers to vertex 100");
  bad = mesh;
  bad.vertices[3].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_ERROR_MENTIONS(writeTetMesh(dir / "bad.mesh", bad), "vertex 4:");
  EXPECT_ERROR_MENTIONS(writeTetMesh(dir / "bad.stl", mesh), "unknown tet mesh format");
  EXPECT_TRUE(dir.files().empty());
}

// ---- VtuSequence

TEST(VtuSequence, WritesFramesAndACollection) {
  TempDir dir;
  const TetMesh rest = makeBoxTets(Vec3::Zero(), Vec3(0.1f, 0.1f, 0.2f), 2, 2, 3);
  VtuSequence sequence(dir / "run.pvd", rest);
  EXPECT_TRUE(fs::exists(dir / "run.pvd"));
  const double times[] = {0.0, 1.0 / 60, 0.1};
  std::vector<std::vector<Vec3>> frames;
  for (int f = 0; f < 3; ++f) {
    std::vector<Vec3> positions = rest.vertices;
    for (std::size_t v = 0; v < positions.size(); ++v)
      positions[v] += Vec3(0.01f * f, -0.003f * f * positions[v].y(), 0.0001f * static_cast<float>(v));
    sequence.addFrame(times[f], positions);
    frames.push_back(positions);
  }
  EXPECT_EQ(sequence.frameCount(), 3u);
  EXPECT_EQ(dir.files(), (std::vector<std::string>{"run.pvd", "run_00000.vtu", "run_00001.vtu", "run_00002.vtu"}));
  for (int f = 0; f < 3; ++f) {
    SCOPED_TRACE(f);
    EXPECT_EQ(sequence.framePath(f), dir / ("run_0000" + std::to_string(f) + ".vtu"));
    expectSameMesh(TetMesh{frames[f], rest.tets}, readTetMesh(sequence.framePath(f)));
    EXPECT_NE(readBytes(sequence.framePath(f)).find("Name=\"displacement\""), std::string::npos);
  }
  const std::string pvd = readBytes(dir / "run.pvd");
  const std::size_t a = pvd.find("timestep=\"0\" group=\"\" part=\"0\" file=\"run_00000.vtu\"");
  const std::size_t b = pvd.find("timestep=\"0.016666666666666666\" group=\"\" part=\"0\" file=\"run_00001.vtu\"");
  const std::size_t c = pvd.find("timestep=\"0.1\" group=\"\" part=\"0\" file=\"run_00002.vtu\"");
  EXPECT_TRUE(a != std::string::npos && b != std::string::npos && c != std::string::npos && a < b && b < c) << pvd;
  EXPECT_NE(pvd.find("type=\"Collection\""), std::string::npos);

  EXPECT_ERROR_MENTIONS(sequence.addFrame(0.05, frames[0]), "does not come after");
  EXPECT_ERROR_MENTIONS(sequence.addFrame(1.0, std::span<const Vec3>(frames[0]).first(3)), "3 positions");
  EXPECT_EQ(sequence.frameCount(), 3u);
  EXPECT_ERROR_MENTIONS(VtuSequence(dir / "missing" / "run.pvd", rest), "cannot write");
}

TEST(VtuSequence, DisplacementIsPositionMinusRest) {
  TempDir dir;
  const TetMesh rest = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 1, 1, 1);
  TetWriteOptions ascii;
  ascii.vtuEncoding = VtuEncoding::Ascii;
  VtuSequence sequence(dir / "d.pvd", rest, ascii);
  std::vector<Vec3> moved = rest.vertices;
  for (Vec3& p : moved) p += Vec3(0.5f, 0.25f, -2);
  sequence.addFrame(0.5, moved);
  const std::string vtu = readBytes(sequence.framePath(0));
  const std::size_t at = vtu.find("Name=\"displacement\"");
  ASSERT_NE(at, std::string::npos);
  std::istringstream values(vtu.substr(vtu.find('>', at) + 1));
  for (std::size_t v = 0; v < rest.vertices.size(); ++v) {
    float x, y, z;
    values >> x >> y >> z;
    EXPECT_EQ(Vec3(x, y, z), Vec3(0.5f, 0.25f, -2)) << v;
  }
}

TEST(VtuSequence, SurfacesAreWrittenAsTriangleCells) {
  TempDir dir;
  const TriMesh cloth{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}, {{0, 1, 2}, {1, 3, 2}}};
  TetWriteOptions ascii;
  ascii.vtuEncoding = VtuEncoding::Ascii;
  VtuSequence sequence(dir / "cloth.pvd", cloth, ascii);
  std::vector<Vec3> moved = cloth.vertices;
  moved[3].z() = 0.5f;
  sequence.addFrame(0.1, moved);
  const std::string vtu = readBytes(sequence.framePath(0));
  EXPECT_NE(vtu.find("NumberOfPoints=\"4\" NumberOfCells=\"2\""), std::string::npos) << vtu;
  const auto array = [&](const char* name) {  // the text of an ASCII DataArray
    const std::size_t at = vtu.find(std::string("Name=\"") + name + "\"");
    const std::size_t begin = vtu.find('>', at) + 1;
    return vtu.substr(begin, vtu.find("</DataArray>", begin) - begin);
  };
  EXPECT_EQ(array("connectivity"), "\n0 1 2\n1 3 2\n        ");
  EXPECT_EQ(array("offsets"), "\n3\n6\n        ");
  EXPECT_EQ(array("types"), "\n5\n5\n        ");  // VTK_TRIANGLE
  EXPECT_NE(array("displacement").find("0 0 0.5"), std::string::npos);
  EXPECT_ERROR_MENTIONS(VtuSequence(dir / "empty.pvd", TriMesh{}), "no triangles");
}

// ---- boundaryFaces

TEST(WriteFile, WholeOrNothing) {
  TempDir dir;
  writeFile(dir / "a.txt", "first");
  writeFile(dir / "a.txt", "second, longer");
  std::ifstream in(dir / "a.txt");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "second, longer");
  EXPECT_NE(testing::errorOf([&] { writeFile(dir / "no_dir" / "b.txt", "x"); }).find("b.txt"), std::string::npos);
  EXPECT_EQ(dir.files(), std::vector<std::string>{"a.txt"});  // no temporary left behind
}

TEST(Boundary, SingleTetFacesPointOutward) {
  const TetMesh tet{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, {{0, 1, 2, 3}}};
  TetMesh inverted = tet;
  std::swap(inverted.tets[0][1], inverted.tets[0][2]);
  for (const TetMesh& mesh : {tet, inverted}) {
    const std::vector<Triangle> faces = boundaryFaces(mesh);
    ASSERT_EQ(faces.size(), 4u);
    for (const Triangle& f : faces) {
      Index opposite = 0;
      while (opposite == f[0] || opposite == f[1] || opposite == f[2]) ++opposite;
      const Vec3 a = mesh.vertices[f[0]], n = (mesh.vertices[f[1]] - a).cross(mesh.vertices[f[2]] - a);
      EXPECT_LT(n.dot(mesh.vertices[opposite] - a), 0) << f[0] << f[1] << f[2];
    }
    expectClosedBoundary(mesh, faces);
  }
}

TEST(Boundary, BoxBoundaryIsClosedDeterministicAndSkipsSharedFaces) {
  const TetMesh box = makeBoxTets(Vec3(-1, 2, 0.5f), Vec3(2, 1, 3), 4, 3, 2);
  const std::vector<Triangle> faces = boundaryFaces(box);
  EXPECT_EQ(faces.size(), 2u * 2 * (4 * 3 + 3 * 2 + 2 * 4));
  expectClosedBoundary(box, faces);
  EXPECT_EQ(boundaryFaces(box), faces);

  const std::vector<Triangle> two = boundaryFaces(kTwoTets);
  EXPECT_EQ(two.size(), 6u);
  for (const Triangle& f : two) {
    Triangle sorted = f;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_NE(sorted, (Triangle{1, 2, 3}));
  }
  TetMesh bad = kTwoTets;
  bad.tets[1][3] = 5;
  EXPECT_ERROR_MENTIONS(boundaryFaces(bad), "tet 2 refers to vertex 6");
}

TEST(Boundary, SurfaceKeepsOnlyBoundaryVerticesAndMapsThemBack) {
  // A 3x3x3 box has one interior vertex row per axis: (4^3 - 2^3) = 56 on the boundary.
  const TetMesh box = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 3, 3, 3);
  std::vector<Index> tetVertex;
  const TriMesh surface = boundarySurface(box, &tetVertex);
  EXPECT_EQ(surface.vertices.size(), 56u);
  ASSERT_EQ(tetVertex.size(), surface.vertices.size());
  const std::vector<Triangle> faces = boundaryFaces(box);
  ASSERT_EQ(surface.triangles.size(), faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(tetVertex[surface.triangles[f][k]], faces[f][k]);
      EXPECT_EQ(surface.vertices[surface.triangles[f][k]], box.vertices[faces[f][k]]);
    }
}

}  // namespace
}  // namespace vrd
