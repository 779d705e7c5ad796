// Tet mesh quality figures against shapes whose angles and ratios are known in closed form.

#include <gtest/gtest.h>

#include "test_support.h"

#include <cmath>
#include <numbers>
#include <numeric>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/mesh/tet_quality.h"

namespace vrd {
namespace {

// Four alternate corners of a cube: a regular tet of edge 2 sqrt(2), positively oriented.
TetMesh regularTet() {
  TetMesh mesh{{{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}, {{0, 1, 2, 3}}};
  const Vec3* v = mesh.vertices.data();
  if (signedTetVolume(v[0], v[1], v[2], v[3]) < 0) std::swap(mesh.tets[0][2], mesh.tets[0][3]);
  return mesh;
}

// The closed surface of the box [0, s]^3 (12 outward triangles).
TriMesh boxSurface(float s) {
  TriMesh mesh;
  for (int i = 0; i < 8; ++i) mesh.vertices.push_back(s * Vec3(float(i & 1), float((i >> 1) & 1), float(i >> 2)));
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

std::size_t histogramTotal(const TetQuality& q) {
  return std::accumulate(q.dihedralHistogram.begin(), q.dihedralHistogram.end(), std::size_t{0});
}

TEST(TetMesh, RemoveUnusedVerticesKeepsTheOthersInOrder) {
  TetMesh mesh;
  mesh.vertices = {Vec3(9, 9, 9), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(8, 8, 8), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  mesh.tets = {{1, 2, 4, 5}};
  EXPECT_EQ(removeUnusedVertices(mesh), 2u);
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.vertices[0], Vec3(0, 0, 0));
  EXPECT_EQ(mesh.vertices[3], Vec3(0, 0, 1));
  EXPECT_EQ(mesh.tets[0], (Tet{0, 1, 2, 3}));
  EXPECT_EQ(removeUnusedVertices(mesh), 0u);  // nothing left to drop
  mesh.tets[0][2] = 7;
  EXPECT_NE(vrd::testing::errorOf([&] { removeUnusedVertices(mesh); }).find("tet 1 refers to vertex 8,"),
            std::string::npos);
}

TEST(TetQuality, RegularTet) {
  const TetQuality q = measureTetQuality(regularTet());
  const double angle = std::acos(1.0 / 3.0) * 180 / std::numbers::pi;  // 70.5288 degrees
  EXPECT_NEAR(angle, 70.5288, 1e-4);
  EXPECT_NEAR(q.minDihedralDeg, angle, 1e-9);
  EXPECT_NEAR(q.maxDihedralDeg, angle, 1e-9);
  EXPECT_NEAR(q.minRadiusEdge, std::sqrt(6.0) / 4, 1e-9);
  EXPECT_NEAR(q.maxRadiusEdge, std::sqrt(6.0) / 4, 1e-9);
  EXPECT_NEAR(q.meanRadiusEdge, 0.6124, 1e-4);
  EXPECT_NEAR(q.volume, 8.0 / 3.0, 1e-12);  // cube 8 minus four corners of 4/3
  EXPECT_EQ(q.dihedralHistogram[7], 6u);
  EXPECT_EQ(q.boundaryFaces, 4u);
  EXPECT_EQ(q.inverted + q.degenerate + q.invalid + q.unusedVertices, 0u);
}

TEST(TetQuality, KuhnBox) {
  // Every Kuhn tet (the path 000-100-110-111 and its permutations) has dihedral angles 45 (x2),
  // 60 (x1) and 90 (x3) degrees, and its circumsphere is the cube's: radius-edge sqrt(3)/2.
  const TetQuality q = measureTetQuality(makeBoxTets(Vec3::Zero(), Vec3::Ones(), 1, 1, 1));
  EXPECT_EQ(q.tets, 6u);
  EXPECT_NEAR(q.minDihedralDeg, 45, 1e-9);
  EXPECT_NEAR(q.maxDihedralDeg, 90, 1e-9);
  EXPECT_EQ(q.dihedralHistogram[4], 12u);                           // 45
  EXPECT_EQ(q.dihedralHistogram[5] + q.dihedralHistogram[6], 6u);   // 60, on a bin edge
  EXPECT_EQ(q.dihedralHistogram[8] + q.dihedralHistogram[9], 18u);  // 90, on a bin edge
  EXPECT_EQ(histogramTotal(q), 36u);
  EXPECT_NEAR(q.minRadiusEdge, std::sqrt(3.0) / 2, 1e-9);
  EXPECT_NEAR(q.maxRadiusEdge, std::sqrt(3.0) / 2, 1e-9);
  EXPECT_NEAR(q.volume, 1.0, 1e-12);
  EXPECT_EQ(q.boundaryFaces, 12u);
  EXPECT_EQ(q.inverted + q.degenerate + q.invalid + q.unusedVertices + q.nonManifoldFaces, 0u);
}

TEST(TetQuality, BoundaryFacesOfABox) {
  const int nx = 3, ny = 2, nz = 4;
  const TetQuality q = measureTetQuality(makeBoxTets(Vec3::Zero(), Vec3(3, 2, 4), nx, ny, nz));
  EXPECT_EQ(q.tets, 6u * nx * ny * nz);
  EXPECT_EQ(q.boundaryFaces, std::size_t(4 * (nx * ny + ny * nz + nz * nx)));
  EXPECT_EQ(q.vertices, std::size_t((nx + 1) * (ny + 1) * (nz + 1)));
  EXPECT_NEAR(q.volume, 24.0, 1e-9);
  EXPECT_NEAR(q.minDihedralDeg, 45, 1e-9);
  EXPECT_NEAR(q.maxDihedralDeg, 90, 1e-9);
}

TEST(TetQuality, InvertedFlatAndInvalidTetsAreCounted) {
  TetMesh mesh = regularTet();
  mesh.tets.push_back({mesh.tets[0][1], mesh.tets[0][0], mesh.tets[0][2], mesh.tets[0][3]});  // inverted
  mesh.vertices.push_back({0.3f, 0.2f, 5});                                                   // 4: unused
  // 5-8 in the plane z = 0: a flat tet.
  for (Vec3 x : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.5f, 0.5f, 0)}) mesh.vertices.push_back(x);
  mesh.tets.push_back({5, 6, 7, 8});
  mesh.tets.push_back({0, 1, 2, 99});  // out of range
  mesh.tets.push_back({0, 1, 1, 2});   // repeated
  const TetQuality q = measureTetQuality(mesh);
  EXPECT_EQ(q.tets, 5u);
  EXPECT_EQ(q.inverted, 1u);
  EXPECT_EQ(q.degenerate, 1u);
  EXPECT_EQ(q.invalid, 2u);
  EXPECT_EQ(q.unusedVertices, 1u);
  // The inverted tet is the mirror of a regular one: same angles, volume cancels.
  EXPECT_NEAR(q.minDihedralDeg, std::acos(1.0 / 3.0) * 180 / std::numbers::pi, 1e-9);
  EXPECT_NEAR(q.maxDihedralDeg, std::acos(1.0 / 3.0) * 180 / std::numbers::pi, 1e-9);
  EXPECT_NEAR(q.volume, 0.0, 1e-12);
  EXPECT_EQ(histogramTotal(q), 12u);
  EXPECT_FALSE(q.table().empty());

  // Nothing measurable: figures are zero, never NaN.
  TetMesh flat{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2, 3}}};
  const TetQuality f = measureTetQuality(flat);
  EXPECT_EQ(f.degenerate, 1u);
  EXPECT_EQ(f.minDihedralDeg, 0);
  EXPECT_EQ(f.maxDihedralDeg, 0);
  EXPECT_EQ(f.maxRadiusEdge, 0);
  EXPECT_EQ(f.meanRadiusEdge, 0);
  EXPECT_FALSE(f.table().empty());
  const TetQuality empty = measureTetQuality(TetMesh{});
  EXPECT_EQ(empty.tets, 0u);
  EXPECT_EQ(empty.boundaryFaces, 0u);
}

TEST(TetQuality, VolumeAgainstASurface) {
  const TetMesh box = makeBoxTets(Vec3::Zero(), Vec3::Constant(2), 3, 3, 3);
  const TriMesh same = boxSurface(2);
  const TetQuality q = measureTetQuality(box, &same);
  ASSERT_TRUE(q.surfaceVolume && q.volumeError);
  EXPECT_NEAR(*q.surfaceVolume, 8.0, 1e-12);
  EXPECT_NEAR(*q.volumeError, 0.0, 1e-6);
  // Tets of a 2-box against the surface of a 2.5-box: 8 / 15.625 - 1.
  const TriMesh larger = boxSurface(2.5f);
  const TetQuality smaller = measureTetQuality(box, &larger);
  EXPECT_NEAR(*smaller.volumeError, 8.0 / 15.625 - 1, 1e-6);
  EXPECT_NE(smaller.table().find("surface volume"), std::string::npos) << smaller.table();
  EXPECT_FALSE(measureTetQuality(box).surfaceVolume);
}

}  // namespace
}  // namespace vrd
