// Surface checks before tetrahedralisation: each defect built from a clean closed surface is
// reported with the right kind and faces; clean surfaces, including the shared meshes, pass.
// Also the triangle-triangle intersection test on its own.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>

#include "mesh/triangle_intersection.h"
#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/mesh/surface_check.h"

namespace vrd {
namespace {

using testing::errorOf;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Reverses every face whose normal points towards `centre` (for convex shapes built below).
void orientOutward(TriMesh& mesh, const Vec3& centre) {
  for (Triangle& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    if ((b - a).cross(c - a).dot(a - centre) < 0) std::swap(t[1], t[2]);
  }
}

// A closed surface of the box [origin, origin + n*h]^3 with n x n quads per side, each split in two.
TriMesh makeCubeSurface(int n = 1, float h = 1.0f, const Vec3& origin = Vec3::Zero()) {
  TriMesh mesh;
  std::map<std::array<int, 3>, Index> ids;
  auto id = [&](std::array<int, 3> c) {
    auto [it, added] = ids.try_emplace(c, Index(mesh.vertices.size()));
    if (added) mesh.vertices.push_back(origin + h * Vec3(float(c[0]), float(c[1]), float(c[2])));
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {0, n})
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> c;
            c[axis] = side;
            c[(axis + 1) % 3] = i + di;
            c[(axis + 2) % 3] = j + dj;
            return id(c);
          };
          mesh.triangles.push_back({at(0, 0), at(1, 0), at(1, 1)});
          mesh.triangles.push_back({at(0, 0), at(1, 1), at(0, 1)});
        }
  orientOutward(mesh, origin + Vec3::Constant(0.5f * n * h));
  return mesh;
}

TriMesh makeOctahedron() {
  TriMesh mesh;
  mesh.vertices = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (Index x : {0, 1})
    for (Index y : {2, 3})
      for (Index z : {4, 5}) mesh.triangles.push_back({x, y, z});
  orientOutward(mesh, Vec3::Zero());
  return mesh;
}

// Appends b to a as a separate component.
TriMesh merged(TriMesh a, const TriMesh& b) {
  const Index offset = Index(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (Triangle t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return a;
}

// Like merged(), but vertices at the same position become one.
TriMesh welded(const TriMesh& a, const TriMesh& b) {
  TriMesh out = a;
  std::vector<Index> map;
  for (const Vec3& x : b.vertices) {
    auto same = std::find(out.vertices.begin(), out.vertices.end(), x);
    map.push_back(Index(same - out.vertices.begin()));
    if (same == out.vertices.end()) out.vertices.push_back(x);
  }
  for (Triangle t : b.triangles) out.triangles.push_back({map[t[0]], map[t[1]], map[t[2]]});
  return out;
}

std::vector<Index> ids(std::initializer_list<Index> list) { return list; }

// Only the `v x y z` and `f i j k` lines of the shared OBJ files (1-based); the library's reader
// is elsewhere. strtod on the whole file keeps it quick under the sanitizers.
TriMesh readObj(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  TriMesh mesh;
  const char* c = text.c_str();
  while (*c) {
    char* end = const_cast<char*>(c) + 1;  // strtof and strtoul skip the blanks before a number
    if (c[0] == 'v' && c[1] == ' ') {
      Vec3 x;
      for (int k = 0; k < 3; ++k) x[k] = std::strtof(end, &end);
      mesh.vertices.push_back(x);
      c = end;
    } else if (c[0] == 'f' && c[1] == ' ') {
      Triangle t;
      for (int k = 0; k < 3; ++k) t[k] = Index(std::strtoul(end, &end, 10) - 1);
      mesh.triangles.push_back(t);
      c = end;
    }
    while (*c && *c != '\n') ++c;
    if (*c) ++c;
  }
  return mesh;
}

std::vector<std::filesystem::path> sharedMeshes() {
  std::vector<std::filesystem::path> paths;
  const std::filesystem::path& dir = testing::kMeshes;
  if (!std::filesystem::is_directory(dir)) return paths;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".obj") paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  return paths;
}

// ---- clean surfaces --------------------------------------------------------------------------

TEST(SurfaceCheck, CubeAndOctahedronPassWithExactFigures) {
  const SurfaceReport cube = checkSurface(makeCubeSurface());
  EXPECT_TRUE(cube.ok()) << cube.summary();
  EXPECT_EQ(cube.vertices, 8u);
  EXPECT_EQ(cube.faces, 12u);
  EXPECT_EQ(cube.edges, 18u);
  EXPECT_EQ(cube.boundaryEdges, 0u);
  EXPECT_EQ(cube.components, 1u);
  EXPECT_EQ(cube.area, 6.0);
  EXPECT_EQ(cube.volume, 1.0);
  EXPECT_EQ(enclosedVolume(makeCubeSurface()), 1.0);
  EXPECT_NO_THROW(requireClosedSurface(makeCubeSurface()));
  EXPECT_TRUE(contains(cube.summary(), "ok")) << cube.summary();

  const SurfaceReport fine = checkSurface(makeCubeSurface(4, 0.25f));
  EXPECT_TRUE(fine.ok()) << fine.summary();
  EXPECT_DOUBLE_EQ(fine.area, 6.0);
  EXPECT_DOUBLE_EQ(fine.volume, 1.0);

  const SurfaceReport octahedron = checkSurface(makeOctahedron());
  EXPECT_TRUE(octahedron.ok()) << octahedron.summary();
  EXPECT_EQ(octahedron.edges, 12u);
  EXPECT_NEAR(octahedron.area, 4 * std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(octahedron.volume, 4.0 / 3.0, 1e-12);
}

TEST(SurfaceCheck, OpenClothPassesWhenOpenIsAllowed) {
  const TriMesh cloth = makeGridCloth(Vec3::Zero(), 4 * Vec3::UnitX(), 3 * Vec3::UnitZ(), 4, 3);
  SurfaceCheckOptions open;
  open.requireClosed = false;
  const SurfaceReport report = checkSurface(cloth, open);
  EXPECT_TRUE(report.ok()) << report.summary();
  EXPECT_EQ(report.boundaryEdges, 2u * (4 + 3));
  EXPECT_EQ(report.edges, 4u * 4 + 5u * 3 + 4u * 3);  // horizontal, vertical, diagonal
  EXPECT_NEAR(report.area, 12.0, 1e-9);

  const SurfaceReport closedRequired = checkSurface(cloth);
  ASSERT_EQ(closedRequired.issues.size(), 1u) << closedRequired.summary();
  EXPECT_EQ(closedRequired.issues[0].defect, SurfaceDefect::BoundaryEdge);
}

TEST(SurfaceCheck, HollowBodyIsNotInsideOut) {
  // A cavity: the inner surface faces inward, so it encloses negative volume on its own.
  TriMesh inner = makeCubeSurface(1, 1.0f, Vec3::Constant(1.0f));
  for (Triangle& t : inner.triangles) std::swap(t[1], t[2]);
  const SurfaceReport report = checkSurface(merged(makeCubeSurface(3), inner));
  EXPECT_TRUE(report.ok()) << report.summary();
  EXPECT_EQ(report.components, 2u);
  EXPECT_DOUBLE_EQ(report.volume, 26.0);
}

TEST(SurfaceCheck, SharedMeshesPass) {
  const auto paths = sharedMeshes();
  if (paths.empty()) GTEST_SKIP() << "no meshes in " << VRDEFORM_SHARED_DIR;
  bool sawFlag = false;
  for (const auto& path : paths) {
    const TriMesh mesh = readObj(path);
    ASSERT_FALSE(mesh.triangles.empty()) << path;
    const auto start = std::chrono::steady_clock::now();
    const SurfaceReport report = checkSurface(mesh);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    testing::record("check_ms." + path.stem().string(), ms);
    if (path.stem() == "flag_plane") {
      sawFlag = true;
      ASSERT_EQ(report.issues.size(), 1u) << report.summary();
      EXPECT_EQ(report.issues[0].defect, SurfaceDefect::BoundaryEdge);
      EXPECT_EQ(report.issues[0].count, 80u);
      EXPECT_TRUE(contains(report.issues[0].message, "80 boundary edges")) << report.issues[0].message;
      EXPECT_EQ(report.boundaryEdges, 80u);
      EXPECT_EQ(report.edges, 2440u);
      EXPECT_EQ(report.components, 1u);
      SurfaceCheckOptions open;
      open.requireClosed = false;
      EXPECT_TRUE(checkSurface(mesh, open).ok());
      EXPECT_THROW(requireClosedSurface(mesh), Error);
    } else {
      EXPECT_TRUE(report.ok()) << path << ": " << report.summary();
      EXPECT_EQ(report.boundaryEdges, 0u) << path;
      EXPECT_EQ(report.components, 1u) << path;
      EXPECT_GT(report.volume, 0) << path;
      EXPECT_NEAR(report.volume, enclosedVolume(mesh), 1e-12 * report.volume) << path;
    }
  }
  EXPECT_TRUE(sawFlag);
}

TEST(SurfaceCheck, SharedMeshesPassRotatedAndFarFromTheOrigin) {
  // Float coordinates far from the origin are flat and smooth only to their rounding: no false
  // intersections from it, and the flag stays merely open.
  const auto paths = sharedMeshes();
  if (paths.empty()) GTEST_SKIP() << "no meshes in " << VRDEFORM_SHARED_DIR;
  const Eigen::Matrix3f rotation = Eigen::AngleAxisf(0.9f, Vec3(1, -2, 3).normalized()).toRotationMatrix();
  int checked = 0;
  for (const auto& path : paths) {
    TriMesh mesh = readObj(path);
    if (mesh.triangles.size() > 2000) continue;  // keep it quick under the sanitizers
    Eigen::AlignedBox3f box;
    for (const Vec3& x : mesh.vertices) box.extend(x);
    const Vec3 offset = 100 * box.sizes().maxCoeff() * Vec3(1, -2, 3);
    for (Vec3& x : mesh.vertices) x = rotation * x + offset;
    const SurfaceReport report = checkSurface(mesh);
    if (path.stem() == "flag_plane") {
      ASSERT_EQ(report.issues.size(), 1u) << report.summary();
      EXPECT_EQ(report.issues[0].defect, SurfaceDefect::BoundaryEdge);
      EXPECT_EQ(report.boundaryEdges, 80u);
    } else {
      EXPECT_TRUE(report.ok()) << path << ": " << report.summary();
      EXPECT_NO_THROW(requireClosedSurface(mesh)) << path;
    }
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

// ---- defects ---------------------------------------------------------------------------------

// The issue of this kind; fails the test when it is missing.
const SurfaceIssue& issueOf(const SurfaceReport& report, SurfaceDefect defect) {
  static const SurfaceIssue none{};
  const SurfaceIssue* issue = report.find(defect);
  EXPECT_NE(issue, nullptr) << "missing " << toString(defect) << " in " << report.summary();
  return issue ? *issue : none;
}

TEST(SurfaceCheck, OpenSurface) {
  TriMesh mesh = makeCubeSurface();
  mesh.triangles.erase(mesh.triangles.begin());  // its three edges now have one face each
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& open = issueOf(report, SurfaceDefect::BoundaryEdge);
  EXPECT_EQ(open.count, 3u);
  EXPECT_EQ(report.boundaryEdges, 3u);
  EXPECT_EQ(open.firstFaces.size(), 3u);
  EXPECT_TRUE(contains(open.message, "surface is open: 3 boundary edges (first faces ")) << open.message;
  EXPECT_TRUE(contains(report.summary(), "boundary edge: " + open.message)) << report.summary();
  // The faces named are those that had a neighbour across the removed face's edges.
  const TriMesh cube = makeCubeSurface();
  for (Index f : open.firstFaces) {
    int sharedVertices = 0;
    for (Index v : mesh.triangles[f])
      sharedVertices += int(std::count(cube.triangles[0].begin(), cube.triangles[0].end(), v));
    EXPECT_EQ(sharedVertices, 2) << "face " << f;
  }
  const std::string msg = errorOf([&] { requireClosedSurface(mesh); });
  EXPECT_TRUE(contains(msg, "3 boundary edges")) << msg;
}

TEST(SurfaceCheck, NonManifoldEdgeOfTwoCubes) {
  // Two cubes welded along one edge: four faces on it.
  const TriMesh mesh = welded(makeCubeSurface(), makeCubeSurface(1, 1.0f, Vec3(1, 1, 0)));
  ASSERT_EQ(mesh.vertices.size(), 14u);
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::NonManifoldEdge);
  EXPECT_EQ(issue.count, 1u);
  EXPECT_EQ(issue.firstFaces.size(), 4u);
  EXPECT_TRUE(contains(issue.message, "1 non-manifold edge (edge ")) << issue.message;
  EXPECT_TRUE(contains(issue.message, " is shared by 4 faces: ")) << issue.message;
  // Every face named has both ends of the shared edge x = y = 1.
  for (Index f : issue.firstFaces) {
    int onEdge = 0;
    for (Index v : mesh.triangles[f]) onEdge += mesh.vertices[v].x() == 1 && mesh.vertices[v].y() == 1;
    EXPECT_EQ(onEdge, 2) << "face " << f;
  }
  EXPECT_THROW(requireClosedSurface(mesh), Error);
}

TEST(SurfaceCheck, FinMakesANonManifoldEdge) {
  TriMesh mesh = makeCubeSurface();
  const Triangle base = mesh.triangles[0];
  const Vec3 middle = 0.5f * (mesh.vertices[base[0]] + mesh.vertices[base[1]]);
  mesh.vertices.push_back(middle + (middle - Vec3::Constant(0.5f)));  // sticking out of the cube
  mesh.triangles.push_back({base[0], base[1], Index(mesh.vertices.size() - 1)});
  const SurfaceReport report = checkSurface(mesh);
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::NonManifoldEdge);
  // Messages number faces and vertices from 1, as OBJ files do.
  EXPECT_TRUE(contains(issue.message, "edge " + std::to_string(std::min(base[0], base[1]) + 1) + "-" +
                                          std::to_string(std::max(base[0], base[1]) + 1) + " is shared by 3 faces: "))
      << issue.message;
  EXPECT_TRUE(contains(issue.message, ": 1, ")) << issue.message;  // faces[0] is face 1
  EXPECT_TRUE(contains(issue.message, "13")) << issue.message;     // the fin, faces[12]
  EXPECT_EQ(issueOf(report, SurfaceDefect::BoundaryEdge).count, 2u);
}

TEST(SurfaceCheck, PinchedVertex) {
  // Two octahedra touching at one vertex: closed, edge-manifold, but not a manifold there.
  TriMesh other = makeOctahedron();
  for (Vec3& x : other.vertices) x += Vec3(2, 0, 0);
  const TriMesh mesh = welded(makeOctahedron(), other);
  ASSERT_EQ(mesh.vertices.size(), 11u);
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::NonManifoldVertex);
  EXPECT_EQ(issue.count, 1u);
  EXPECT_TRUE(contains(issue.message, "meet only at vertex 1,")) << issue.message;
}

TEST(SurfaceCheck, OneFlippedFace) {
  TriMesh mesh = makeCubeSurface(2, 0.5f);
  std::swap(mesh.triangles[5][0], mesh.triangles[5][1]);
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::InconsistentOrientation);
  EXPECT_EQ(issue.count, 3u);
  EXPECT_EQ(issue.firstFaces, ids({5}));
  EXPECT_TRUE(contains(issue.message, "3 edges are traversed in the same direction")) << issue.message;
  EXPECT_TRUE(contains(issue.message, "reverse face 6")) << issue.message;
  EXPECT_THROW(requireClosedSurface(mesh), Error);
}

TEST(SurfaceCheck, AllFacesFlippedIsInsideOut) {
  TriMesh mesh = makeCubeSurface();
  for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::InwardOrientation);
  EXPECT_EQ(report.volume, -1.0);
  EXPECT_EQ(issue.firstFaces, ids({0}));
  EXPECT_TRUE(contains(issue.message, "inside out")) << issue.message;
  EXPECT_TRUE(contains(errorOf([&] { requireClosedSurface(mesh); }), "inside out"));

  // One inside-out body beside a correct one (not inside it): only that component is named.
  TriMesh apart = mesh;
  for (Vec3& x : apart.vertices) x += Vec3(3, 0, 0);
  const SurfaceReport two = checkSurface(merged(makeCubeSurface(), apart));
  ASSERT_EQ(two.issues.size(), 1u) << two.summary();
  EXPECT_EQ(issueOf(two, SurfaceDefect::InwardOrientation).firstFaces, ids({12}));
  EXPECT_TRUE(contains(two.issues[0].message, "1 of 2 components")) << two.issues[0].message;
}

TEST(SurfaceCheck, OverlappingCubesIntersect) {
  const TriMesh mesh = merged(makeCubeSurface(), makeCubeSurface(1, 1.0f, Vec3::Constant(0.5f)));
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::SelfIntersection);
  EXPECT_GT(issue.count, 0u);
  EXPECT_TRUE(contains(issue.message, "pairs of faces intersect (faces ")) << issue.message;
  // Each cube alone is fine, so every pair has one face of each.
  ASSERT_FALSE(issue.firstFaces.empty());
  EXPECT_LT(issue.firstFaces.front(), 12u);
  EXPECT_GE(issue.firstFaces.back(), 12u);
  EXPECT_TRUE(contains(errorOf([&] { requireClosedSurface(mesh); }), "intersect"));

  SurfaceCheckOptions fast;
  fast.checkSelfIntersection = false;
  EXPECT_TRUE(checkSurface(mesh, fast).ok());
}

TEST(SurfaceCheck, VertexPushedThroughTheOppositeSide) {
  TriMesh mesh = makeCubeSurface(4);
  // The centre of the top side goes below the bottom: its faces pierce the bottom side.
  const Index apex =
      Index(std::find(mesh.vertices.begin(), mesh.vertices.end(), Vec3(2, 2, 4)) - mesh.vertices.begin());
  ASSERT_LT(apex, mesh.vertices.size());
  mesh.vertices[apex].z() = -1;
  const SurfaceReport report = checkSurface(mesh);
  ASSERT_EQ(report.issues.size(), 1u) << report.summary();
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::SelfIntersection);
  bool namesSpike = false;
  for (Index f : issue.firstFaces)
    namesSpike = namesSpike || std::count(mesh.triangles[f].begin(), mesh.triangles[f].end(), apex) > 0;
  EXPECT_TRUE(namesSpike) << issue.message;
}

TEST(SurfaceCheck, NonFiniteCoordinate) {
  TriMesh mesh = makeCubeSurface();
  mesh.vertices[3].x() = std::numeric_limits<float>::quiet_NaN();
  const SurfaceReport report = checkSurface(mesh);
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::NonFinite);
  EXPECT_EQ(issue.count, 1u);
  EXPECT_EQ(issue.firstFaces, ids({3}));  // the vertex
  EXPECT_TRUE(contains(issue.message, "vertex 4 = (nan, ")) << issue.message;
  Index user = 0;
  while (std::count(mesh.triangles[user].begin(), mesh.triangles[user].end(), 3) == 0) ++user;
  EXPECT_TRUE(contains(issue.message, "in face " + std::to_string(user + 1))) << issue.message;
  EXPECT_TRUE(std::isfinite(report.area));
  EXPECT_TRUE(std::isfinite(report.volume));
  EXPECT_TRUE(contains(errorOf([&] { requireClosedSurface(mesh); }), "vertex 4 "));

  mesh.vertices[5].z() = std::numeric_limits<float>::infinity();
  EXPECT_EQ(issueOf(checkSurface(mesh), SurfaceDefect::NonFinite).firstFaces, ids({3, 5}));

  // A coordinate of 1e38 is a number, but out of range: said so, not taken for degenerate faces.
  TriMesh huge = makeCubeSurface();
  huge.vertices[2].y() = 1e38f;
  const SurfaceReport far = checkSurface(huge);
  const SurfaceIssue& range = issueOf(far, SurfaceDefect::NonFinite);
  EXPECT_EQ(range.firstFaces, ids({2}));
  EXPECT_TRUE(contains(range.message, "vertex 3 = (")) << range.message;
  EXPECT_TRUE(contains(range.message, "out-of-range")) << range.message;
  for (const SurfaceIssue& i : far.issues) EXPECT_NE(i.defect, SurfaceDefect::DegenerateFace) << i.message;
}

TEST(SurfaceCheck, DegenerateFaces) {
  TriMesh repeated = makeCubeSurface();
  repeated.triangles[4][2] = repeated.triangles[4][0];
  const SurfaceReport report = checkSurface(repeated);
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::DegenerateFace);
  EXPECT_EQ(issue.firstFaces, ids({4}));
  EXPECT_TRUE(contains(issue.message, "face 5 uses vertex " + std::to_string(repeated.triangles[4][0] + 1) + " twice"))
      << issue.message;
  EXPECT_THROW(requireClosedSurface(repeated), Error);

  TriMesh collinear;
  collinear.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}};
  collinear.triangles = {{0, 1, 3}, {1, 0, 2}};
  SurfaceCheckOptions open;
  open.requireClosed = false;
  const SurfaceReport flat = checkSurface(collinear, open);
  ASSERT_EQ(flat.issues.size(), 1u) << flat.summary();
  EXPECT_EQ(issueOf(flat, SurfaceDefect::DegenerateFace).firstFaces, ids({1}));
  EXPECT_TRUE(contains(flat.issues[0].message, "face 2 has zero area")) << flat.issues[0].message;
}

TEST(SurfaceCheck, OutOfRangeIndex) {
  TriMesh mesh = makeCubeSurface();
  mesh.triangles[7][2] = 99;
  const SurfaceReport report = checkSurface(mesh);
  const SurfaceIssue& issue = issueOf(report, SurfaceDefect::BadIndex);
  EXPECT_EQ(issue.firstFaces, ids({7}));
  EXPECT_EQ(issue.message, "face 8 refers to vertex 100, but there are only 8 vertices");
  EXPECT_TRUE(std::isfinite(enclosedVolume(mesh)));  // the face is skipped
  EXPECT_TRUE(contains(errorOf([&] { requireClosedSurface(mesh); }), "face 8 refers to vertex 100"));
}

TEST(SurfaceCheck, EmptyMesh) {
  const SurfaceReport report = checkSurface(TriMesh{});
  ASSERT_EQ(report.issues.size(), 1u);
  EXPECT_EQ(report.issues[0].defect, SurfaceDefect::Empty);
  EXPECT_FALSE(report.ok());
  TriMesh pointsOnly;
  pointsOnly.vertices = {{0, 0, 0}};
  EXPECT_EQ(checkSurface(pointsOnly).issues[0].defect, SurfaceDefect::Empty);
  EXPECT_TRUE(contains(errorOf([] { requireClosedSurface(TriMesh{}); }), "no faces"));
}

// ---- triangle-triangle test ------------------------------------------------------------------

const Triangle3d kBase{Vec3d(0, 0, 0), Vec3d(1, 0, 0), Vec3d(0, 1, 0)};

Triangle3d moved(const Triangle3d& t, const Vec3d& by) { return {t[0] + by, t[1] + by, t[2] + by}; }

bool intersect(const Triangle3d& p, const Triangle3d& q) {
  const double tol = intersectionTolerance(p, q);
  const bool pq = trianglesIntersect(p, q, tol), qp = trianglesIntersect(q, p, tol);
  EXPECT_EQ(pq, qp) << "not symmetric";
  return pq;
}

TEST(TriTri, SeparateAndTouching) {
  EXPECT_FALSE(intersect(kBase, moved(kBase, {0, 0, 1})));
  EXPECT_FALSE(intersect(kBase, moved(kBase, {2, 0, 0})));
  // A vertex resting on the interior, and just above it.
  const Triangle3d tip{Vec3d(0.2, 0.2, 0), Vec3d(0.5, 0.2, 1), Vec3d(0.2, 0.5, 1)};
  EXPECT_TRUE(intersect(kBase, tip));
  EXPECT_FALSE(intersect(kBase, moved(tip, {0, 0, 1e-3})));
  EXPECT_TRUE(intersect(kBase, moved(tip, {0, 0, -1e-3})));
  // Vertex to vertex.
  EXPECT_TRUE(intersect(kBase, moved(tip, {-0.2, -0.2, 0})));
}

TEST(TriTri, Crossing) {
  const Triangle3d wall{Vec3d(0.25, 0.25, -1), Vec3d(0.25, -0.5, 1), Vec3d(0.25, 1, 1)};
  EXPECT_TRUE(intersect(kBase, wall));
  EXPECT_FALSE(intersect(kBase, moved(wall, {0.8, 0, 0})));  // beyond the hypotenuse at x = 1.05
  // An edge piercing the interior.
  const Triangle3d spear{Vec3d(0.3, 0.3, -1), Vec3d(0.3, 0.3, 1), Vec3d(2, 2, 0.5)};
  EXPECT_TRUE(intersect(kBase, spear));
}

TEST(TriTri, Coplanar) {
  EXPECT_TRUE(intersect(kBase, moved(kBase, {0.3, 0.3, 0})));                                   // partly overlapping
  EXPECT_TRUE(intersect(kBase, {Vec3d(0.1, 0.1, 0), Vec3d(0.3, 0.1, 0), Vec3d(0.1, 0.3, 0)}));  // inside
  EXPECT_FALSE(intersect(kBase, moved(kBase, {0.6, 0.6, 0})));                                  // beyond the hypotenuse
  EXPECT_TRUE(intersect(kBase, moved(kBase, {1, 0, 0})));                                       // touching at a vertex
  // The same in a tilted plane, rounded to float as mesh data is.
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(0.7, Vec3d(1, 2, 3).normalized()) * Eigen::AngleAxisd(0.3, Vec3d::UnitX())).matrix();
  auto tilt = [&](const Triangle3d& t) {
    Triangle3d out;
    for (int k = 0; k < 3; ++k) out[k] = (r * t[k] + Vec3d(5, -3, 2)).cast<float>().cast<double>();
    return out;
  };
  EXPECT_TRUE(intersect(tilt(kBase), tilt(moved(kBase, {0.3, 0.3, 0}))));
  EXPECT_FALSE(intersect(tilt(kBase), tilt(moved(kBase, {0.6, 0.6, 0}))));
  // Mirrored across the hypotenuse: neighbours in a flat mesh that share no vertex index.
  const Triangle3d mirror{Vec3d(1, 0.01, 0), Vec3d(1, 1, 0), Vec3d(0.01, 1, 0)};
  EXPECT_FALSE(intersect(tilt(kBase), tilt(mirror)));
}

TEST(TriTri, SharedEdge) {
  const Triangle ids{0, 1, 2}, other{1, 0, 3};
  auto shared = [&](const Vec3d& d) {
    const Triangle3d q{kBase[1], kBase[0], d};
    return facesIntersect(kBase, ids, q, other, intersectionTolerance(kBase, q));
  };
  EXPECT_FALSE(shared({0.5, -1, 0}));    // flat neighbour
  EXPECT_FALSE(shared({0.5, 0.5, 1}));   // bent
  EXPECT_FALSE(shared({0.5, 1, 0.01}));  // sharply folded, still apart
  EXPECT_TRUE(shared({0.5, 1, 0}));      // folded flat onto the first face
  EXPECT_TRUE(shared({0.2, 0.2, 0}));
  // The plain test counts the shared edge as contact.
  EXPECT_TRUE(intersect(kBase, {kBase[1], kBase[0], Vec3d(0.5, -1, 0)}));
  // The same three vertices twice.
  EXPECT_TRUE(facesIntersect(kBase, ids, {kBase[1], kBase[2], kBase[0]}, {1, 2, 0}, 1e-9));
}

TEST(TriTri, SharedVertex) {
  const Triangle ids{0, 1, 2}, other{0, 3, 4};
  auto shared = [&](const Vec3d& d, const Vec3d& e) {
    const Triangle3d q{kBase[0], d, e};
    return facesIntersect(kBase, ids, q, other, intersectionTolerance(kBase, q));
  };
  EXPECT_FALSE(shared({-1, 0, 0.5}, {0, -1, 0.5}));          // apart
  EXPECT_FALSE(shared({-1, 0, 0}, {0, -1, 0}));              // flat, opposite corner
  EXPECT_FALSE(shared({1, 0, 1}, {0, 1, 1}));                // above, over the first face
  EXPECT_TRUE(shared({0.3, 0.3, 1}, {0.3, 0.3, -1}));        // its far edge pierces the first face
  EXPECT_TRUE(shared({2, 2, 1}, {2, 2, -1}));                // the first face's far edge pierces it
  EXPECT_TRUE(shared({0.5, 0.2, 0}, {0.2, 0.5, 0}));         // flat, overlapping
  EXPECT_FALSE(shared({0.5, 0.2, 1e-3}, {0.2, 0.5, 1e-3}));  // just above it: only the vertex is shared
}

// An independent reference for pairs in general position (no vertex on the other plane): each
// triangle meets the other's plane in a segment of the planes' common line, and the triangles
// meet when the two segments overlap (Möller's interval test, without tolerances).
bool intervalReference(const Triangle3d& p, const Triangle3d& q) {
  auto distances = [](const Triangle3d& t, const Triangle3d& plane) {
    const Vec3d n = (plane[1] - plane[0]).cross(plane[2] - plane[0]);
    return std::array<double, 3>{n.dot(t[0] - plane[0]), n.dot(t[1] - plane[0]), n.dot(t[2] - plane[0])};
  };
  const std::array<double, 3> dq = distances(q, p), dp = distances(p, q);
  auto oneSide = [](const std::array<double, 3>& d) { return (d[0] > 0) == (d[1] > 0) && (d[1] > 0) == (d[2] > 0); };
  if (oneSide(dq) || oneSide(dp)) return false;
  const Vec3d line = (p[1] - p[0]).cross(p[2] - p[0]).cross((q[1] - q[0]).cross(q[2] - q[0]));
  auto interval = [&](const Triangle3d& t, const std::array<double, 3>& d) {
    std::vector<double> s;
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if ((d[i] > 0) != (d[j] > 0)) s.push_back(line.dot(t[i] + (t[j] - t[i]) * (d[i] / (d[i] - d[j]))));
    }
    return std::pair<double, double>(std::min(s[0], s[1]), std::max(s[0], s[1]));
  };
  const auto [pLo, pHi] = interval(p, dp);
  const auto [qLo, qHi] = interval(q, dq);
  return std::max(pLo, qLo) <= std::min(pHi, qHi);
}

TEST(TriTri, AgreesWithIntervalReference) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  auto random = [&] {
    return Triangle3d{Vec3d(u(rng), u(rng), u(rng)), Vec3d(u(rng), u(rng), u(rng)), Vec3d(u(rng), u(rng), u(rng))};
  };
  int hits = 0;
  for (int n = 0; n < 3000; ++n) {
    const Triangle3d p = random(), q = random();
    const bool expected = intervalReference(p, q);
    ASSERT_EQ(intersect(p, q), expected) << n;
    hits += expected;
  }
  EXPECT_GT(hits, 300);
  EXPECT_LT(hits, 2700);
}

}  // namespace
}  // namespace vrd
