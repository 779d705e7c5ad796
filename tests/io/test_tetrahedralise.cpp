// Both meshers on every closed shared mesh: positive tets, the surface's volume, counts on
// request, bounded angles; and TetGen's failures (missing, crashing, hanging, garbage) as errors.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tetrahedralise.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/isosurface_stuffing.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/mesh/surface_check.h"
#include "vrdeform/mesh/tet_pieces.h"
#include "vrdeform/mesh/tet_quality.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;
using testing::kMeshes;
const char* const kClosedMeshes[] = {
    "bear_coarse.obj",   "bunny_coarse.obj", "liver_coarse.obj", "jelly_blobby_coarse.obj",
    "sphere_coarse.obj", "sphere.obj",       "bear.obj",         "bunny.obj",
    "liver.obj",         "jelly_blobby.obj"};

double meshVolume(const TetMesh& mesh) {
  double v = 0;
  for (const Tet& t : mesh.tets)
    v += signedTetVolume(mesh.vertices[t[0]].cast<double>().eval(), mesh.vertices[t[1]].cast<double>().eval(),
                         mesh.vertices[t[2]].cast<double>().eval(), mesh.vertices[t[3]].cast<double>().eval());
  return v;
}

// Every boundary edge is traversed as often in one direction as in the other: closed and
// consistently oriented. (Two parts of a coarse mesh may touch along an edge: 2 + 2.)
bool closedAndConsistent(const std::vector<Triangle>& faces) {
  std::map<std::pair<Index, Index>, int> directed;
  for (const Triangle& f : faces)
    for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (back == directed.end() || back->second != count) return false;
  }
  return !faces.empty();
}

void expectSoundMesh(const TetMesh& mesh, const TriMesh& surface, double volumeTolerance) {
  EXPECT_NO_THROW(validateTetMesh(mesh));  // positive, non-degenerate tets
  const TetQuality q = measureTetQuality(mesh, &surface);
  EXPECT_EQ(q.inverted, 0u);
  EXPECT_EQ(q.degenerate, 0u);
  EXPECT_EQ(q.nonManifoldFaces, 0u);
  ASSERT_TRUE(q.volumeError.has_value());
  EXPECT_LT(std::abs(*q.volumeError), volumeTolerance) << "mesh volume " << q.volume << " vs " << *q.surfaceVolume;
  EXPECT_TRUE(closedAndConsistent(boundaryFaces(mesh)));
}

bool haveTetGen() { return std::system("command -v tetgen >/dev/null 2>&1") == 0; }

TEST(Tetrahedralise, BuiltinMeshesEveryClosedSharedMeshToTheCountAndVolume) {
  for (const char* name : kClosedMeshes) {
    SCOPED_TRACE(name);
    const TriMesh surface = readSurface(kMeshes / name);
    const Tetrahedralisation result = tetrahedralise(surface, {.mesher = Mesher::Builtin, .targetTets = 1500});
    EXPECT_NEAR(double(result.mesh.tets.size()), 1500.0, 0.15 * 1500);
    expectSoundMesh(result.mesh, surface, 0.02);
    // Isosurface stuffing bounds the dihedral angles (Labelle and Shewchuk: 10.7 to 164.8 degrees
    // for smooth surfaces; polyhedral inputs with sharp creases may cost a little).
    const TetQuality q = measureTetQuality(result.mesh);
    EXPECT_GT(q.minDihedralDeg, 5.0);
    EXPECT_LT(q.maxDihedralDeg, 170.0);
  }
}

TEST(Tetrahedralise, BuiltinGivesOneFaceConnectedPieceAtEveryCount) {
  // A part thinner than a lattice cell (the bunny's ears) can come out as fragments: loose tets,
  // or tets joined to the body only along an edge or at a vertex, which would fall off or hinge.
  // They are dropped and counted; what remains is one piece whose tets all share faces.
  for (const char* name : kClosedMeshes) {
    const TriMesh surface = readSurface(kMeshes / name);
    for (std::size_t target : {700u, 3000u, 5000u}) {
      SCOPED_TRACE(fmt::format("{} at {} tets", name, target));
      const Tetrahedralisation r = tetrahedralise(surface, {.mesher = Mesher::Builtin, .targetTets = target});
      EXPECT_EQ(facePieces(r.mesh).count, 1u);
      EXPECT_LT(r.dropped.share, 0.01);
      EXPECT_EQ(droppedMessage(r).empty(), r.dropped.pieces == 0);
    }
  }
  // A cell at which the bunny's thin parts fragment (most cells of about 0.5-1.2 do): the pieces
  // are found, dropped, counted, and the volume is still the surface's.
  const TriMesh bunny = readSurface(kMeshes / "bunny.obj");
  const Stuffing made = stuffIsosurface(bunny, {0.816, true});
  EXPECT_GE(made.dropped.pieces, 1u);
  EXPECT_GE(made.dropped.tets, made.dropped.pieces);
  EXPECT_GT(made.dropped.share, 0.0);
  EXPECT_EQ(facePieces(made.mesh).count, 1u);
  EXPECT_NEAR(meshVolume(made.mesh), enclosedVolume(bunny), 1e-3 * enclosedVolume(bunny));
}

TEST(Tetrahedralise, TetGenMeshesEveryClosedSharedMeshToTheCountAndVolume) {
  ASSERT_TRUE(haveTetGen()) << "TetGen is missing: scripts/install-deps.sh installs it";
  for (const char* name : kClosedMeshes) {
    SCOPED_TRACE(name);
    const TriMesh surface = readSurface(kMeshes / name);
    // TetGen keeps every input vertex, and its quality refinement adds more: the coarse surfaces
    // need 3,000-6,000 tets at radius-edge 1.5, the fine ones far more. These get a target; the
    // fine ones one run without bounds.
    const bool coarse = surface.vertices.size() < 1000;
    const std::size_t target = coarse ? 8000 : 0;
    const Tetrahedralisation result =
        tetrahedralise(surface, {.mesher = Mesher::TetGen, .targetTets = target, .radiusEdge = coarse ? 1.5 : 0});
    if (coarse) {
      EXPECT_NEAR(double(result.mesh.tets.size()), double(target), 0.15 * target) << result.runs << " runs";
      EXPECT_EQ(result.radiusEdge, 1.5);
    }
    // TetGen fills the input polyhedron exactly; only float rounding remains.
    expectSoundMesh(result.mesh, surface, 1e-5);
  }
}

TEST(Tetrahedralise, BuiltinVolumeErrorWithoutCorrectionShrinksAsTheCellSquared) {
  // Boundary vertices on the surface: an inscribed solid, short by O(h^2).
  const TriMesh surface = readSurface(kMeshes / "liver_coarse.obj");
  const double exact = enclosedVolume(surface);
  const double h = 20;  // mm
  const double coarse = meshVolume(stuffIsosurface(surface, {h, false}).mesh);
  const double fine = meshVolume(stuffIsosurface(surface, {h / 2, false}).mesh);
  const double errCoarse = (exact - coarse) / exact, errFine = (exact - fine) / exact;
  EXPECT_GT(errCoarse, 0);
  EXPECT_GT(errFine, 0);
  EXPECT_LT(errFine, errCoarse / 2.5);  // second order would be /4; the surface's own facets blur it
  EXPECT_LT(errFine, 0.02);
}

TEST(Tetrahedralise, BuiltinBoundaryVerticesLieOnTheSurface) {
  // With no volume correction, every boundary vertex is a cut point or a warped lattice vertex:
  // on the surface, up to float rounding. Checked on a unit sphere of 320 faces.
  const TriMesh surface = readSurface(kMeshes / "sphere_coarse.obj");
  const TetMesh mesh = stuffIsosurface(surface, {0.1, false}).mesh;
  std::set<Index> boundary;
  for (const Triangle& f : boundaryFaces(mesh)) boundary.insert(f.begin(), f.end());
  ASSERT_GT(boundary.size(), 100u);
  for (Index v : boundary) {
    // Distance to the facet plane nearest in angle: the icosphere's radius 0.5 bounds it.
    const double r = mesh.vertices[v].cast<double>().norm();
    EXPECT_LE(r, 0.5 + 1e-6);
    EXPECT_GE(r, 0.5 * std::cos(0.32));  // facets of a 320-face icosphere sag by at most ~5%
  }
}

TEST(Tetrahedralise, CountControlHitsSeveralTargets) {
  const TriMesh surface = readSurface(kMeshes / "bunny_coarse.obj");
  for (std::size_t target : {1000u, 10000u}) {
    const Tetrahedralisation r = tetrahedralise(surface, {.targetTets = target});
    EXPECT_NEAR(double(r.mesh.tets.size()), double(target), 0.15 * target);
  }
  const Tetrahedralisation fixedBound = tetrahedralise(surface, {.maxVolume = 0.5});
  EXPECT_EQ(fixedBound.runs, 1);
  EXPECT_NEAR(fixedBound.mesh.tets.size(), 12 * 192.8 / 12 / 0.5, 0.25 * 192.8 / 0.5);  // volume / bound, +- boundary
}

TEST(Tetrahedralise, TetGenTargetBelowWhatTheSurfaceNeedsGivesTheFewestTets) {
  ASSERT_TRUE(haveTetGen());
  const TriMesh surface = readSurface(kMeshes / "sphere_coarse.obj");
  const Tetrahedralisation fewest = tetrahedralise(surface, {.mesher = Mesher::TetGen, .targetTets = 50});
  const TetMesh unbounded = runTetGen(surface, 0, 0, {});
  EXPECT_EQ(fewest.mesh.tets.size(), unbounded.tets.size());
  EXPECT_EQ(fewest.radiusEdge, 0.0);
  EXPECT_GT(fewest.mesh.tets.size(), 50u);
}

TEST(Tetrahedralise, DefectiveSurfacesAreRejectedBeforeMeshing) {
  TriMesh open = readSurface(kMeshes / "flag_plane.obj");
  EXPECT_THROW(tetrahedralise(open), Error);
  TriMesh flipped = readSurface(kMeshes / "sphere_coarse.obj");
  std::swap(flipped.triangles[5][0], flipped.triangles[5][1]);
  for (Mesher m : {Mesher::Builtin, Mesher::TetGen}) {
    try {
      tetrahedralise(flipped, {.mesher = m});
      ADD_FAILURE() << "accepted a surface with a flipped face";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("5"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(tetrahedralise(readSurface(kMeshes / "sphere_coarse.obj"), {.maxVolume = -1}), Error);
  EXPECT_THROW(tetrahedralise(readSurface(kMeshes / "sphere_coarse.obj"), {.maxVolume = NAN}), Error);
}

// A stand-in for TetGen: a shell script doing something bad.
class FakeTetGen : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("vrd_fake_tetgen_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string script(const std::string& body) {
    const fs::path path = dir_ / "tetgen";
    std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
    fs::permissions(path, fs::perms::owner_all);
    return path.string();
  }
  std::string failureOf(const std::string& program, double timeout = 30) {
    TetrahedraliseOptions options{.mesher = Mesher::TetGen, .maxVolume = 0.01};
    options.tetgenProgram = program;
    options.timeoutSeconds = timeout;
    try {
      tetrahedralise(readSurface(kMeshes / "sphere_coarse.obj"), options);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  }
  fs::path dir_;
};

TEST_F(FakeTetGen, MissingProgramSaysHowToGetIt) {
  EXPECT_NE(failureOf((dir_ / "no-such-tetgen").string()).find("install it"), std::string::npos);
}

TEST_F(FakeTetGen, CrashIsReportedNotInherited) {
  const std::string message = failureOf(script("echo meshing...; kill -SEGV $$"));
  EXPECT_NE(message.find("crashed (signal 11"), std::string::npos) << message;
  EXPECT_NE(message.find("meshing..."), std::string::npos) << message;
}

TEST_F(FakeTetGen, FailureShowsItsOutput) {
  const std::string message = failureOf(script("echo 'Error:  A self-intersection was detected.'; exit 3"));
  EXPECT_NE(message.find("exit status 3"), std::string::npos) << message;
  EXPECT_NE(message.find("self-intersection"), std::string::npos) << message;
}

TEST_F(FakeTetGen, HangIsKilledAtTheTimeout) {
  const std::string message = failureOf(script("exec sleep 30"), 0.3);
  EXPECT_NE(message.find("did not finish within 0.3 s"), std::string::npos) << message;
}

TEST_F(FakeTetGen, GarbageOutputIsAnError) {
  // The input is the last argument; write nonsense where the mesh should be.
  const std::string message =
      failureOf(script("for last; do :; done; base=${last%.smesh}; echo '4 3 0 0 banana' > $base.1.node; "
                       "head -c 300 /dev/urandom > $base.1.ele"));
  EXPECT_NE(message.find("could not be read"), std::string::npos) << message;
}

}  // namespace
}  // namespace vrd
