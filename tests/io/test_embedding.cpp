// Render-mesh embedding: rest and affine deformations are reproduced exactly (inside and outside
// the tet mesh), normals turn with the cofactor, collapsed tets stay finite, bad input is an error.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tetrahedralise.h"
#include "vrdeform/mesh/embedding.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/particles.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using Mat3d = Mat3T<double>;

using testing::kMeshes;
TriMesh bear() { return readSurface(kMeshes / "bear.obj"); }

double diagonal(const std::vector<Vec3>& points) {
  Eigen::AlignedBox3f box;
  for (const Vec3& p : points) box.extend(p);
  return box.diagonal().norm();
}

std::vector<Vec3> transformed(const std::vector<Vec3>& points, const Mat3d& a, const Vec3d& b) {
  std::vector<Vec3> out;
  for (const Vec3& p : points) out.push_back((a * p.cast<double>() + b).cast<float>());
  return out;
}

std::vector<Vec3> exactNormals(const TriMesh& mesh, const std::vector<Vec3>& positions) {
  std::vector<Vec3> normals(positions.size());
  computeVertexNormals(mesh.triangles, positions, normals);
  return normals;
}

struct Output {
  std::vector<Vec3> positions, normals;
};

Output update(const Embedding& e, const std::vector<Vec3>& tetPositions) {
  Output out{std::vector<Vec3>(e.vertexCount()), std::vector<Vec3>(e.vertexCount())};
  e.update(tetPositions, out.positions, out.normals);
  return out;
}

// Every position within tol of the expected one, and every normal within normalTol of its expected
// direction.
void expectNear(const Output& out, const std::vector<Vec3>& positions, double tol, const std::vector<Vec3>& normals,
                double normalTol) {
  double worst = 0, worstNormal = 0;
  for (std::size_t v = 0; v < positions.size(); ++v) {
    // Error first: a NaN error stays.
    worst = std::max(double((out.positions[v] - positions[v]).norm()), worst);
    worstNormal = std::max(double((out.normals[v] - normals[v]).norm()), worstNormal);
  }
  EXPECT_LE(worst, tol);
  EXPECT_LE(worstNormal, normalTol);
  testing::record("worst_position_error", worst);
  testing::record("worst_normal_error", worstNormal);
}

void expectFinite(const Output& out) {
  for (std::size_t v = 0; v < out.positions.size(); ++v) {
    ASSERT_TRUE(isFinite(out.positions[v])) << "position " << v;
    ASSERT_TRUE(isFinite(out.normals[v])) << "normal " << v;
    ASSERT_NEAR(out.normals[v].norm(), 1.0f, 1e-5f) << "normal " << v;
  }
}

// Non-symmetric, with shear and stretch, det > 0.
Mat3d shearStretch() {
  Mat3d a;
  a << 1.3, 0.4, -0.2, 0.1, 0.8, 0.3, -0.25, 0.15, 1.1;
  return a;
}

// A deformation's expected normals: cof(A) n, i.e. A^-T n up to the positive factor det A.
std::vector<Vec3> turnedNormals(const std::vector<Vec3>& normals, const Mat3d& a) {
  const Mat3d cof = a.determinant() * a.inverse().transpose();
  std::vector<Vec3> out;
  for (const Vec3& n : normals) out.push_back((cof * n.cast<double>()).normalized().cast<float>());
  return out;
}

// An affine map of the tet vertices moves every render vertex by the same map and turns its normal.
// normalTol: float rounding of cof(Ds) grows with the tets' condition; 1e-5 for good shapes.
void expectAffineExact(const TetMesh& tets, const TriMesh& render, const Embedding& e, const Mat3d& a, const Vec3d& b,
                       double normalTol = 1e-5) {
  const Output out = update(e, transformed(tets.vertices, a, b));
  const auto positions = transformed(render.vertices, a, b);
  expectNear(out, positions, 1e-5 * diagonal(positions), turnedNormals(exactNormals(render, render.vertices), a),
             normalTol);
  // The same as the exact normals of the deformed surface (area weights scale uniformly).
  expectNear(out, positions, 1e-5 * diagonal(positions), exactNormals(render, positions), normalTol);
}

constexpr EmbeddingSimd kSimd[] = {EmbeddingSimd::best, EmbeddingSimd::sse};

TEST(Embedding, ReproducesRestPositionsAndNormals) {
  const TetMesh tets = makeBoxTets(Vec3(-1.05f, -1.05f, -1.05f), Vec3(2.1f, 2.1f, 2.1f), 4, 4, 4);
  for (float radius : {1.0f, 1.4f}) {  // inside the box, then partly outside
    SCOPED_TRACE(radius);
    const TriMesh sphere = makeUvSphere(Vec3(0.05f, -0.02f, 0.03f), radius, 24, 48);
    const Embedding e = Embedding::bind(tets, sphere);
    EXPECT_EQ(e.vertexCount(), sphere.vertices.size());
    EXPECT_EQ(e.tetVertexCount(), tets.vertices.size());
    if (radius == 1.0f) {
      EXPECT_EQ(e.outsideCount(), 0u);
      EXPECT_EQ(e.maxOutsideDistance(), 0.0);
    } else {
      EXPECT_GT(e.outsideCount(), sphere.vertices.size() / 4);
      EXPECT_NEAR(e.maxOutsideDistance(), 0.05 + 1.4 - 1.05, 1e-3);  // the vertex on the +x axis
    }
    expectNear(update(e, tets.vertices), sphere.vertices, 1e-6 * diagonal(sphere.vertices),
               exactNormals(sphere, sphere.vertices), 1e-5);
  }
}

TEST(Embedding, BindingWeightsReproduceRestPositions) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3::Zero(), 1.2f, 12, 24);
  const Embedding e = Embedding::bind(tets, sphere);
  for (std::size_t v = 0; v < sphere.vertices.size(); ++v) {
    const VertexBinding b = e.binding(v);
    ASSERT_LT(b.tet, tets.tets.size());
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < 4; ++k) p += b.weights[k] * tets.vertices[tets.tets[b.tet][k]];
    EXPECT_LE((p - sphere.vertices[v]).norm(), 1e-5f) << "vertex " << v;
    if (sphere.vertices[v].cwiseAbs().maxCoeff() < 0.99f) {  // inside: a convex combination
      EXPECT_GE(*std::min_element(b.weights.begin(), b.weights.end()), -1e-6f) << "vertex " << v;
    }
  }
  EXPECT_THROW(e.binding(sphere.vertices.size()), Error);
}

TEST(Embedding, OutsideVerticesBindToTheNearestTet) {
  // A sphere entirely beside the unit box: its farthest vertex (2.25, 0.5, 0.5) is 1.25 away.
  const TetMesh tets = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 2, 2, 2);
  const TriMesh sphere = makeUvSphere(Vec3(2.0f, 0.5f, 0.5f), 0.25f, 8, 16);
  const Embedding e = Embedding::bind(tets, sphere);
  EXPECT_EQ(e.outsideCount(), sphere.vertices.size());
  EXPECT_NEAR(e.maxOutsideDistance(), 1.25, 1e-6);
  for (std::size_t v = 0; v < sphere.vertices.size(); ++v) {
    // The bound tet touches the face x = 1 (where the nearest tets are).
    const Tet& tet = tets.tets[e.binding(v).tet];
    EXPECT_TRUE(std::any_of(tet.begin(), tet.end(), [&](Index i) { return tets.vertices[i].x() == 1.0f; }));
  }
  expectAffineExact(tets, sphere, e, shearStretch(), Vec3d(0.3, -0.2, 0.5));
}

TEST(Embedding, AffineDeformationIsExactInsideAndOutside) {
  const Mat3d a = shearStretch();
  ASSERT_GT(a.determinant(), 0);
  const TetMesh tets = makeBoxTets(Vec3(-1.05f, -1.05f, -1.05f), Vec3(2.1f, 2.1f, 2.1f), 4, 4, 4);
  for (float radius : {1.0f, 1.4f}) {
    SCOPED_TRACE(radius);
    const TriMesh sphere = makeUvSphere(Vec3(0.05f, -0.02f, 0.03f), radius, 24, 48);
    Embedding e = Embedding::bind(tets, sphere);
    for (EmbeddingSimd simd : kSimd) {
      e.setSimd(simd);
      expectAffineExact(tets, sphere, e, a, Vec3d(0.3, -0.2, 0.5));
    }
  }
}

TEST(Embedding, RotationRotatesNormals) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 0.9f, 16, 32);
  const Embedding e = Embedding::bind(tets, sphere);
  const Mat3d r = Eigen::AngleAxisd(2.0, Vec3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Output out = update(e, transformed(tets.vertices, r, Vec3d(1, 2, 3)));
  const auto rest = exactNormals(sphere, sphere.vertices);
  double worst = 0;
  for (std::size_t v = 0; v < rest.size(); ++v)
    worst = std::max(worst, (out.normals[v].cast<double>() - r * rest[v].cast<double>()).norm());
  EXPECT_LE(worst, 1e-5);
}

TEST(Embedding, ReflectionFlipsNormalsLikeTheDeformedTriangles) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 1.1f, 16, 32);
  const Embedding e = Embedding::bind(tets, sphere);
  const Mat3d mirror = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  const Output out = update(e, transformed(tets.vertices, mirror, Vec3d::Zero()));
  expectFinite(out);
  const auto positions = transformed(sphere.vertices, mirror, Vec3d::Zero());
  // cof(M) = -M: the triangles turn inside out, and so do the embedded normals.
  expectNear(out, positions, 1e-6, exactNormals(sphere, positions), 1e-5);
}

class EmbeddingKernels : public ::testing::TestWithParam<EmbeddingSimd> {};
INSTANTIATE_TEST_SUITE_P(EmbeddingSimd, EmbeddingKernels, ::testing::ValuesIn(kSimd));

TEST_P(EmbeddingKernels, CollapsedTetsGiveFiniteOutput) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 1.1f, 16, 32);
  Embedding e = Embedding::bind(tets, sphere);
  e.setSimd(GetParam());
  const auto rest = exactNormals(sphere, sphere.vertices);

  // To a point: every vertex there, normals fall back to the rest normals.
  const Output point = update(e, std::vector<Vec3>(tets.vertices.size(), Vec3(1, 2, 3)));
  expectNear(point, std::vector<Vec3>(sphere.vertices.size(), Vec3(1, 2, 3)), 1e-6, rest, 1e-6);

  // To the plane z = 0: cof(F) n is along z; the triangles flatten with +-z normals.
  const Mat3d flat = Eigen::Vector3d(1, 1, 0).asDiagonal();
  const Output plane = update(e, transformed(tets.vertices, flat, Vec3d::Zero()));
  expectFinite(plane);
  for (std::size_t v = 0; v < rest.size(); ++v) {
    EXPECT_NEAR(plane.positions[v].z(), 0.0f, 1e-6f);
    if (std::abs(rest[v].z()) > 1e-3f) {
      EXPECT_NEAR(plane.normals[v].z(), rest[v].z() > 0 ? 1.0f : -1.0f, 1e-5f) << "vertex " << v;
    }
  }
  // cof(F) n = 0 exactly (rest normals in the plane z = 0, like the equator's): F n instead.
  TriMesh disc = makeUvSphere(Vec3::Zero(), 0.9f, 2, 16);
  disc.vertices[0].z() = 0.01f;  // a double cone, its rim on z = 0 with normals in the plane
  disc.vertices.back().z() = -0.01f;
  Embedding coneEmbedding = Embedding::bind(tets, disc);
  coneEmbedding.setSimd(GetParam());
  const Output cone = update(coneEmbedding, transformed(tets.vertices, flat, Vec3d::Zero()));
  expectFinite(cone);
  const auto coneRest = exactNormals(disc, disc.vertices);
  for (std::size_t v = 1; v + 1 < disc.vertices.size(); ++v) {
    ASSERT_NEAR(coneRest[v].z(), 0.0f, 1e-5f);
    EXPECT_LE((cone.normals[v] - Vec3(coneRest[v].x(), coneRest[v].y(), 0).normalized()).norm(), 1e-5f)
        << "vertex " << v;
  }

  // To the x axis, and random garbage with inverted and flat tets.
  expectFinite(update(e, transformed(tets.vertices, Eigen::Vector3d(1, 0, 0).asDiagonal(), Vec3d::Zero())));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Vec3> garbage(tets.vertices.size());
  for (Vec3& p : garbage) p = Vec3(u(rng), u(rng), u(rng));
  for (std::size_t i = 0; i < garbage.size(); i += 3) garbage[i] = garbage[0];
  expectFinite(update(e, garbage));
}

TEST(Embedding, NearlyFlatTetsKeepAccurateNormals) {
  // Squashed 1e5 times: the tets take the double-precision path, which must agree with the map.
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 0.9f, 16, 32);
  const Mat3d a = Eigen::Vector3d(1, 1, 1e-5).asDiagonal();
  const Output out = update(Embedding::bind(tets, sphere), transformed(tets.vertices, a, Vec3d::Zero()));
  expectFinite(out);
  const auto positions = transformed(sphere.vertices, a, Vec3d::Zero());
  const auto rest = exactNormals(sphere, sphere.vertices), expected = turnedNormals(rest, a);
  for (std::size_t v = 0; v < positions.size(); ++v) {
    EXPECT_LE((out.positions[v] - positions[v]).norm(), 1e-6f) << "vertex " << v;
    // Near the equator float rounding of the rest normal is amplified up to 1e5 times.
    if (std::abs(rest[v].z()) > 0.05f) {
      EXPECT_LE((out.normals[v] - expected[v]).norm(), 1e-5f) << "vertex " << v;
    }
  }
}

TEST_P(EmbeddingKernels, MatchesTheBarycentricFormUnderRandomDeformation) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 4, 4, 4);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 1.1f, 20, 160);  // 3,042 vertices: a partial last block
  Embedding e = Embedding::bind(tets, sphere);
  e.setSimd(GetParam());
  EXPECT_GT(e.mixedBlockShare(), 0.1);  // both kinds of blocks are exercised
  EXPECT_LT(e.mixedBlockShare(), 0.9);
  testing::record("mixed_block_share", e.mixedBlockShare());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.08f, 0.08f);
  std::vector<Vec3> x = tets.vertices;
  for (Vec3& p : x) p += Vec3(u(rng), u(rng), u(rng));
  const Output out = update(e, x);
  const auto rest = exactNormals(sphere, sphere.vertices);
  double worst = 0, worstNormal = 0;
  for (std::size_t v = 0; v < sphere.vertices.size(); ++v) {
    const VertexBinding b = e.binding(v);
    const Tet& tet = tets.tets[b.tet];
    Vec3d p = Vec3d::Zero();
    for (int k = 0; k < 4; ++k) p += double(b.weights[k]) * x[tet[k]].cast<double>();
    Mat3d ds, dm;
    for (int k = 0; k < 3; ++k) {
      ds.col(k) = (x[tet[k + 1]] - x[tet[0]]).cast<double>();
      dm.col(k) = (tets.vertices[tet[k + 1]] - tets.vertices[tet[0]]).cast<double>();
    }
    const Mat3d f = ds * dm.inverse();
    const Vec3d n = (f.determinant() * f.inverse().transpose() * rest[v].cast<double>()).normalized();
    worst = std::max(worst, (out.positions[v].cast<double>() - p).norm());
    worstNormal = std::max(worstNormal, (out.normals[v].cast<double>() - n).norm());
  }
  EXPECT_LE(worst, 1e-5);
  EXPECT_LE(worstNormal, 1e-5);
}

TEST_P(EmbeddingKernels, UntouchedTetsKeepTheirVertices) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 4, 4, 4);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 0.9f, 20, 40);
  Embedding e = Embedding::bind(tets, sphere);
  e.setSimd(GetParam());
  std::vector<Vec3> x = tets.vertices;
  for (Vec3& p : x)
    if (p.x() > 0.1f) p += Vec3(0.2f * p.x(), -0.1f, 0.3f * p.y());
  const Output rest = update(e, tets.vertices), out = update(e, x);
  std::size_t still = 0, moved = 0;
  for (std::size_t v = 0; v < sphere.vertices.size(); ++v) {
    const Tet& tet = tets.tets[e.binding(v).tet];
    const bool untouched = std::all_of(tet.begin(), tet.end(), [&](Index i) { return x[i] == tets.vertices[i]; });
    if (untouched) {
      ++still;
      EXPECT_EQ(out.positions[v], rest.positions[v]) << "vertex " << v;
      EXPECT_EQ(out.normals[v], rest.normals[v]) << "vertex " << v;
      EXPECT_LE((out.positions[v] - sphere.vertices[v]).norm(), 1e-6f) << "vertex " << v;
    } else if (sphere.vertices[v].x() > 0.6f) {
      ++moved;
      EXPECT_GT((out.positions[v] - sphere.vertices[v]).norm(), 0.05f) << "vertex " << v;
    }
  }
  EXPECT_GT(still, sphere.vertices.size() / 3);
  EXPECT_GT(moved, 0u);
}

TEST(Embedding, KernelsAgree) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 4, 4, 4);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 1.1f, 20, 41);
  Embedding e = Embedding::bind(tets, sphere);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-0.1f, 0.1f);
  std::vector<Vec3> x = tets.vertices;
  for (Vec3& p : x) p += Vec3(u(rng), u(rng), u(rng));
  e.setSimd(EmbeddingSimd::sse);
  EXPECT_FALSE(e.usesAvx2());
  const Output sse = update(e, x);
  e.setSimd(EmbeddingSimd::best);
  testing::record("avx2", e.usesAvx2());
  // Only FMA rounding may differ.
  expectNear(update(e, x), sse.positions, 1e-6, sse.normals, 1e-6);
}

TEST(Embedding, ReadsSolverParticlesInPlace) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 3, 3, 3);
  const TriMesh sphere = makeUvSphere(Vec3(0.1f, 0, 0), 1.1f, 12, 24);
  const Embedding e = Embedding::bind(tets, sphere);
  const std::vector<Vec3> x = transformed(tets.vertices, shearStretch(), Vec3d(1, 0, 0));
  std::vector<Point> points;
  for (const Vec3& p : x) points.push_back({p, 2.0f});
  Output out{std::vector<Vec3>(e.vertexCount()), std::vector<Vec3>(e.vertexCount())};
  e.update(std::span<const Point>(points), out.positions, out.normals);
  const Output expected = update(e, x);
  EXPECT_EQ(out.positions, expected.positions);
  EXPECT_EQ(out.normals, expected.normals);
  // Positions only.
  std::vector<Vec3> positions(e.vertexCount());
  e.update(x, positions, {});
  EXPECT_EQ(positions, expected.positions);

  // A body's slice of a world's particles (a second body first, so the slice has an offset).
  World world;
  world.addBody(makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Ones(), 1, 1, 1), Material{}));
  const BodyId body = world.addBody(makeSoftBody(tets, Material{}), Vec3(0, 2, 0));
  const auto slice =
      std::span<const Point>(world.particles().x).subspan(world.particleIndex(body, 0), tets.vertices.size());
  e.update(slice, out.positions, out.normals);
  expectNear(out, transformed(sphere.vertices, Mat3d::Identity(), Vec3d(0, 2, 0)), 1e-6,
             exactNormals(sphere, sphere.vertices), 1e-5);
}

TEST(Embedding, BearFollowsAffineMapsInAndAroundItsBox) {
  const TriMesh mesh = bear();
  ASSERT_EQ(mesh.vertices.size(), 13826u);
  Eigen::AlignedBox3f box;
  for (const Vec3& p : mesh.vertices) box.extend(p);
  const Mat3d a = shearStretch();
  const Vec3d b(-0.4, 0.25, 0.1);
  {
    SCOPED_TRACE("box around the bear");
    const Vec3 margin = 0.01f * box.sizes();
    const TetMesh tets = makeBoxTetsNear(box.min() - margin, box.sizes() + 2 * margin, 1500);
    EXPECT_NEAR(double(tets.tets.size()), 1500.0, 300.0);
    const Embedding e = Embedding::bind(tets, mesh);
    EXPECT_EQ(e.outsideCount(), 0u);
    expectNear(update(e, tets.vertices), mesh.vertices, 1e-6 * diagonal(mesh.vertices),
               exactNormals(mesh, mesh.vertices), 1e-5);
    expectAffineExact(tets, mesh, e, a, b);
  }
  {
    SCOPED_TRACE("box smaller than the bear");
    const TetMesh tets = makeBoxTetsNear(box.min() + 0.2f * box.sizes(), 0.6f * box.sizes(), 1500);
    const Embedding e = Embedding::bind(tets, mesh);
    EXPECT_GT(e.outsideCount(), mesh.vertices.size() / 10);
    EXPECT_LT(e.outsideCount(), mesh.vertices.size());
    EXPECT_GT(e.maxOutsideDistance(), 0.1 * box.sizes().minCoeff());
    testing::record("outside_vertices", double(e.outsideCount()));
    testing::record("max_outside_distance", e.maxOutsideDistance());
    expectNear(update(e, tets.vertices), mesh.vertices, 1e-6 * diagonal(mesh.vertices),
               exactNormals(mesh, mesh.vertices), 1e-5);
    expectAffineExact(tets, mesh, e, a, b);
  }
}

TEST(Embedding, BearFollowsItsCoarseTetBody) {
  // The paper's setup: bear.obj (13,826 vertices) rendered over ~1,300 tets that TetGen makes from
  // bear_coarse.obj with no bounds. The coarse surface lies mostly just inside the fine one, so
  // most render vertices sit slightly outside the tets and extrapolate from the nearest one.
  const TriMesh render = bear();
  const TetMesh tets =
      tetrahedralise(readSurface(kMeshes / "bear_coarse.obj"), {.mesher = Mesher::TetGen, .radiusEdge = 0}).mesh;
  EXPECT_NEAR(double(tets.tets.size()), 1300.0, 200.0);
  const Embedding e = Embedding::bind(tets, render);
  EXPECT_EQ(e.vertexCount(), 13826u);
  testing::record("outside_vertices", double(e.outsideCount()));
  testing::record("max_outside_distance", e.maxOutsideDistance());
  EXPECT_LT(e.maxOutsideDistance(), 0.02 * diagonal(render.vertices));  // the coarse surface's sag
  // Without a quality bound TetGen leaves slivers (dihedral angles down to 0.1 degrees), whose
  // ill-conditioned shape matrices cost normals a few 1e-5 in float.
  expectNear(update(e, tets.vertices), render.vertices, 1e-6 * diagonal(render.vertices),
             exactNormals(render, render.vertices), 1e-4);
  expectAffineExact(tets, render, e, shearStretch(), Vec3d(0.3, -0.2, 0.1), 1e-4);
}

TEST(Embedding, InvalidInputIsAnError) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 2, 2, 2);
  const TriMesh sphere = makeUvSphere(Vec3::Zero(), 0.9f, 8, 16);
  EXPECT_THROW(Embedding::bind(tets, TriMesh{}), Error);
  TriMesh nan = sphere;
  nan.vertices[5].y() = std::nanf("");
  EXPECT_THROW(Embedding::bind(tets, nan), Error);
  TriMesh badIndex = sphere;
  badIndex.triangles[3][1] = static_cast<Index>(sphere.vertices.size());
  EXPECT_THROW(Embedding::bind(tets, badIndex), Error);
  EXPECT_THROW(Embedding::bind(TetMesh{}, sphere), Error);
  TetMesh inverted = tets;
  std::swap(inverted.tets[4][0], inverted.tets[4][1]);
  EXPECT_THROW(Embedding::bind(inverted, sphere), Error);

  const Embedding e = Embedding::bind(tets, sphere);
  std::vector<Vec3> positions(e.vertexCount()), normals(e.vertexCount());
  std::vector<Vec3> x = tets.vertices;
  EXPECT_NO_THROW(e.update(x, positions, normals));
  x.pop_back();
  EXPECT_THROW(e.update(x, positions, normals), Error);
  x.push_back(Vec3::Zero());
  x.push_back(Vec3::Zero());
  EXPECT_THROW(e.update(x, positions, normals), Error);
  x.pop_back();
  std::vector<Vec3> small(e.vertexCount() - 1);
  EXPECT_THROW(e.update(x, small, normals), Error);
  EXPECT_THROW(e.update(x, positions, small), Error);
  EXPECT_THROW(computeVertexNormals(sphere.triangles, sphere.vertices, small), Error);
  EXPECT_THROW(computeVertexNormals(badIndex.triangles, sphere.vertices, normals), Error);
}

TEST(Embedding, UnboundEmbeddingIsEmpty) {
  const Embedding e;
  EXPECT_EQ(e.vertexCount(), 0u);
  EXPECT_NO_THROW(e.update(std::span<const Vec3>{}, {}, {}));
  EXPECT_THROW(e.update(std::vector<Vec3>(4), {}, {}), Error);
}

TEST(Embedding, LooseRenderVerticesGetZeroNormals) {
  const TetMesh tets = makeBoxTets(Vec3(-1, -1, -1), Vec3(2, 2, 2), 2, 2, 2);
  TriMesh sphere = makeUvSphere(Vec3::Zero(), 0.9f, 8, 16);
  sphere.vertices.push_back(Vec3(0.1f, 0.2f, 0.3f));  // in no triangle
  const Embedding e = Embedding::bind(tets, sphere);
  for (const Mat3d& a : {Mat3d(Mat3d::Identity()), Mat3d(Eigen::Vector3d(1, 1, 0).asDiagonal())}) {
    const Output out = update(e, transformed(tets.vertices, a, Vec3d::Zero()));
    EXPECT_EQ(out.normals.back(), Vec3::Zero());
    EXPECT_LE((out.positions.back() - (a * Vec3d(0.1, 0.2, 0.3)).cast<float>()).norm(), 1e-6f);
  }
}

}  // namespace
}  // namespace vrd
