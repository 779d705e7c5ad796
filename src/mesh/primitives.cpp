#include "vrdeform/mesh/primitives.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "vrdeform/error.h"

namespace vrd {

TetMesh makeBoxTets(const Vec3& origin, const Vec3& size, int nx, int ny, int nz) {
  if (nx < 1 || ny < 1 || nz < 1) throw Error("makeBoxTets: cell counts must be at least 1");
  TetMesh mesh;
  auto id = [&](int i, int j, int k) { return Index((k * (ny + 1) + j) * (nx + 1) + i); };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.vertices.push_back(origin + size.cwiseProduct(Vec3(float(i) / nx, float(j) / ny, float(k) / nz)));

  // Kuhn subdivision: one tet per axis order (a, b, c), walking from corner 000 to corner 111.
  static constexpr int kOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mesh.tets.reserve(std::size_t(6) * nx * ny * nz);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& order : kOrders) {
          int c[3] = {i, j, k};
          Tet tet;
          tet[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[order[s]];
            tet[s + 1] = id(c[0], c[1], c[2]);
          }
          const Vec3* v = mesh.vertices.data();
          if (signedTetVolume(v[tet[0]], v[tet[1]], v[tet[2]], v[tet[3]]) < 0) std::swap(tet[2], tet[3]);
          mesh.tets.push_back(tet);
        }
  return mesh;
}

TetMesh makeBoxTetsNear(const Vec3& origin, const Vec3& size, int targetTets) {
  if (targetTets < 6) throw Error("makeBoxTetsNear: need at least 6 tets");
  // Cell edge h so that 6 * (sx/h)(sy/h)(sz/h) = target.
  const double h = std::cbrt(6.0 * double(size.x()) * size.y() * size.z() / targetTets);
  auto cells = [&](float extent) { return std::max(1, int(std::lround(extent / h))); };
  return makeBoxTets(origin, size, cells(size.x()), cells(size.y()), cells(size.z()));
}

TriMesh makeGridCloth(const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis, int nu, int nv) {
  if (nu < 1 || nv < 1) throw Error("makeGridCloth: cell counts must be at least 1");
  TriMesh mesh;
  for (int iv = 0; iv <= nv; ++iv)
    for (int iu = 0; iu <= nu; ++iu)
      mesh.vertices.push_back(origin + uAxis * (float(iu) / nu) + vAxis * (float(iv) / nv));
  auto id = [&](int iu, int iv) { return Index(iv * (nu + 1) + iu); };
  for (int iv = 0; iv < nv; ++iv)
    for (int iu = 0; iu < nu; ++iu) {
      mesh.triangles.push_back({id(iu, iv), id(iu + 1, iv), id(iu + 1, iv + 1)});
      mesh.triangles.push_back({id(iu, iv), id(iu + 1, iv + 1), id(iu, iv + 1)});
    }
  return mesh;
}

TriMesh makeUvSphere(const Vec3& centre, float radius, int rings, int segments) {
  if (rings < 2 || segments < 3) throw Error("makeUvSphere: needs at least 2 rings and 3 segments");
  TriMesh m;
  m.vertices.push_back(centre + Vec3(0, 0, radius));
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double theta = std::numbers::pi * i / rings, phi = 2 * std::numbers::pi * j / segments;
      m.vertices.push_back(
          centre +
          radius *
              Vec3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)).cast<float>());
    }
  const Index south = static_cast<Index>(m.vertices.size());
  m.vertices.push_back(centre - Vec3(0, 0, radius));
  auto ring = [&](int i, int j) { return static_cast<Index>(1 + (i - 1) * segments + j % segments); };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
    m.triangles.push_back({ring(rings - 1, j), south, ring(rings - 1, j + 1)});
  }
  return m;
}

Flag makeFlag(const Vec3& poleTop, float width, float height, int nu, int nv) {
  Flag flag{makeGridCloth(poleTop, Vec3(width, 0, 0), Vec3(0, -height, 0), nu, nv), {}};
  for (int iv = 0; iv <= nv; ++iv) flag.pinned.push_back(Index(iv * (nu + 1)));
  return flag;
}

}  // namespace vrd
