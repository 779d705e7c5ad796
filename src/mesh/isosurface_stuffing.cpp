#include "vrdeform/mesh/isosurface_stuffing.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/surface_check.h"
#include "vrdeform/mesh/surface_query.h"
#include "vrdeform/mesh/vertex_normals.h"

namespace vrd {
namespace {

// Warping thresholds of Labelle and Shewchuk: a cut point closer to a lattice vertex than this
// fraction of its edge pulls the vertex onto the surface. Long (black) edges join two cube
// corners or two cube centres; short (red) edges join a corner to a centre.
constexpr double kAlphaLong = 0.24999, kAlphaShort = 0.41189;

enum Sign : signed char { kInside = -1, kOnSurface = 0, kOutside = 1 };

std::uint64_t edgeKey(Index a, Index b) { return a < b ? (std::uint64_t{a} << 32) | b : (std::uint64_t{b} << 32) | a; }

// The body-centred cubic lattice over a box: cube corners (i, j, k) and cube centres.
struct Lattice {
  Vec3d origin;
  double h = 0;
  int nx = 0, ny = 0, nz = 0;  // cubes per axis

  std::size_t cornerCount() const { return std::size_t(nx + 1) * (ny + 1) * (nz + 1); }
  std::size_t vertexCount() const { return cornerCount() + std::size_t(nx) * ny * nz; }
  Index corner(int i, int j, int k) const { return Index(i + (nx + 1) * (j + (ny + 1) * std::size_t(k))); }
  Index centre(int i, int j, int k) const { return Index(cornerCount() + i + nx * (j + ny * std::size_t(k))); }
  bool isCentre(Index v) const { return v >= cornerCount(); }
  Vec3d position(Index v) const {
    if (isCentre(v)) {
      const std::size_t c = v - cornerCount();
      return origin + h * Vec3d(c % nx + 0.5, (c / nx) % ny + 0.5, c / (std::size_t(nx) * ny) + 0.5);
    }
    return origin + h * Vec3d(v % (nx + 1), (v / (nx + 1)) % (ny + 1), v / (std::size_t(nx + 1) * (ny + 1)));
  }
};

// Every BCC tet: two neighbouring cube centres and one edge of the square face between them.
std::vector<Tet> latticeTets(const Lattice& l) {
  std::vector<Tet> tets;
  const int n[3] = {l.nx, l.ny, l.nz};
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int k = 0; k < l.nz; ++k)
      for (int j = 0; j < l.ny; ++j)
        for (int i = 0; i < l.nx; ++i) {
          int c[3] = {i, j, k};
          if (c[axis] + 1 >= n[axis]) continue;
          const Index a = l.centre(i, j, k);
          c[axis] += 1;
          const Index b = l.centre(c[0], c[1], c[2]);
          // The shared face lies at corner coordinate c[axis]; walk its square.
          auto faceCorner = [&](int du, int dv) {
            int q[3] = {c[0], c[1], c[2]};
            q[u] += du;
            q[v] += dv;
            return l.corner(q[0], q[1], q[2]);
          };
          const Index square[4] = {faceCorner(0, 0), faceCorner(1, 0), faceCorner(1, 1), faceCorner(0, 1)};
          for (int e = 0; e < 4; ++e) tets.push_back({a, b, square[e], square[(e + 1) % 4]});
        }
  }
  return tets;
}

struct Stuffer {
  const SurfaceQuery& query;
  Lattice lattice;
  std::vector<Vec3d> position;                     // lattice vertices (warped), then cut points
  std::vector<Sign> sign;                          // per lattice vertex
  std::unordered_map<std::uint64_t, Index> cutOf;  // edge -> cut point id

  void classify() {
    const std::size_t n = lattice.vertexCount();
    position.resize(n);
    sign.resize(n);
    for (Index v = 0; v < n; ++v) {
      position[v] = lattice.position(v);
      sign[v] = query.inside(position[v]) ? kInside : kOutside;
    }
  }

  // Cut points on edges whose ends lie on opposite sides; warps vertices too close to one.
  void cutAndWarp(const std::vector<Tet>& tets) {
    struct Cut {
      Index a, b;
      double t;  // fraction from a to b
    };
    std::vector<Cut> cuts;
    std::unordered_map<std::uint64_t, bool> seen;
    for (const Tet& tet : tets)
      for (int p = 0; p < 4; ++p)
        for (int q = p + 1; q < 4; ++q) {
          const Index a = tet[p], b = tet[q];
          if (sign[a] == sign[b] || !seen.emplace(edgeKey(a, b), true).second) continue;
          const Index in = sign[a] == kInside ? a : b, out = in == a ? b : a;
          const double t = query.firstCrossing(position[in], position[out]).value_or(0.5);
          cuts.push_back({in, out, t});
        }
    std::vector<Vec3d> cutPosition(cuts.size());
    std::vector<std::vector<Index>> cutsAt(sign.size());
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      cutPosition[c] = position[cuts[c].a] + cuts[c].t * (position[cuts[c].b] - position[cuts[c].a]);
      cutsAt[cuts[c].a].push_back(static_cast<Index>(c));
      cutsAt[cuts[c].b].push_back(static_cast<Index>(c));
    }
    // Warp, vertex by vertex: a vertex moves onto its nearest violating cut point and joins the
    // surface; cut points on edges to an already warped vertex are gone.
    for (Index v = 0; v < sign.size(); ++v) {
      double nearest = HUGE_VAL;
      Index chosen = 0;
      for (Index c : cutsAt[v]) {
        const Cut& cut = cuts[c];
        if (sign[cut.a] == kOnSurface || sign[cut.b] == kOnSurface) continue;
        const bool shortEdge = lattice.isCentre(cut.a) != lattice.isCentre(cut.b);
        const double length = (position[cut.b] - position[cut.a]).norm();
        const double distance = (v == cut.a ? cut.t : 1 - cut.t) * length;
        if (distance < (shortEdge ? kAlphaShort : kAlphaLong) * length && distance < nearest) {
          nearest = distance;
          chosen = c;
        }
      }
      if (nearest == HUGE_VAL) continue;
      position[v] = cutPosition[chosen];
      sign[v] = kOnSurface;
    }
    // Surviving cut points: edges still joining inside and outside.
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      if (sign[cuts[c].a] != kInside || sign[cuts[c].b] != kOutside) continue;
      cutOf.emplace(edgeKey(cuts[c].a, cuts[c].b), static_cast<Index>(position.size()));
      position.push_back(cutPosition[c]);
    }
  }

  Index cut(Index a, Index b) const { return cutOf.at(edgeKey(a, b)); }

  // A polygon of the inside part, as ids (lattice vertices, then cut points).
  using Polygon = std::vector<Index>;

  // Splits a polygon into triangles fanned from its smallest id. Neighbouring tets see the same
  // ids on a shared face, so they split it the same way and the mesh stays conforming.
  static void fanFromMinimum(const Polygon& polygon, std::vector<std::array<Index, 3>>& out) {
    const std::size_t n = polygon.size();
    const std::size_t m = std::min_element(polygon.begin(), polygon.end()) - polygon.begin();
    for (std::size_t k = 1; k + 1 < n; ++k) out.push_back({polygon[m], polygon[(m + k) % n], polygon[(m + k + 1) % n]});
  }

  // Fills the inside part of a lattice tet that the surface cuts: the convex polytope of its
  // inside and on-surface vertices and the cut points, coned from its smallest id over the
  // triangulated faces that do not contain that id.
  void fillCut(const Tet& tet, std::vector<Tet>& out) const {
    static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    std::vector<Polygon> faces;
    for (const auto& face : kFaces) {
      Polygon polygon;
      for (int k = 0; k < 3; ++k) {
        const Index a = tet[face[k]], b = tet[face[(k + 1) % 3]];
        if (sign[a] != kOutside) polygon.push_back(a);
        if (sign[a] * sign[b] < 0) polygon.push_back(cut(a, b));
      }
      if (polygon.size() >= 3) faces.push_back(polygon);
    }
    // The face on the surface: on-surface vertices and cut points, ordered around their centroid.
    Polygon cap;
    for (int p = 0; p < 4; ++p) {
      if (sign[tet[p]] == kOnSurface) cap.push_back(tet[p]);
      for (int q = p + 1; q < 4; ++q)
        if (sign[tet[p]] * sign[tet[q]] < 0) cap.push_back(cut(tet[p], tet[q]));
    }
    if (cap.size() >= 3) {
      Vec3d centre = Vec3d::Zero();
      for (Index v : cap) centre += position[v] / double(cap.size());
      const Vec3d normal = (position[cap[1]] - position[cap[0]]).cross(position[cap[2]] - position[cap[0]]);
      const Vec3d e0 = (position[cap[0]] - centre).normalized(), e1 = normal.normalized().cross(e0);
      std::sort(cap.begin(), cap.end(), [&](Index a, Index b) {
        const Vec3d da = position[a] - centre, db = position[b] - centre;
        return std::atan2(da.dot(e1), da.dot(e0)) < std::atan2(db.dot(e1), db.dot(e0));
      });
      faces.push_back(cap);
    }
    Index apex = ~Index{0};
    for (const Polygon& f : faces) apex = std::min(apex, *std::min_element(f.begin(), f.end()));
    std::vector<std::array<Index, 3>> triangles;
    for (const Polygon& f : faces)
      if (std::find(f.begin(), f.end(), apex) == f.end()) fanFromMinimum(f, triangles);
    for (const auto& t : triangles) out.push_back({apex, t[0], t[1], t[2]});
  }
};

// Moves the boundary vertices along their area-weighted normals by one offset, found by secant
// steps, so the tets enclose `targetVolume`; backs off if a tet would flatten.
void restoreVolume(TetMesh& mesh, double targetVolume) {
  const std::vector<Triangle> boundary = boundaryFaces(mesh);
  std::vector<Vec3> unitNormal(mesh.vertices.size());  // zero inside
  computeVertexNormals(boundary, mesh.vertices, unitNormal);
  std::vector<Vec3d> rest(mesh.vertices.size()), normal(mesh.vertices.size());
  for (std::size_t v = 0; v < rest.size(); ++v) {
    rest[v] = mesh.vertices[v].cast<double>();
    normal[v] = unitNormal[v].cast<double>();
  }
  // Volume and smallest tet volume with the boundary moved by `offset`.
  auto measure = [&](double offset) {
    double volume = 0, smallest = HUGE_VAL;
    for (const Tet& t : mesh.tets) {
      Vec3d p[4];
      for (int k = 0; k < 4; ++k) p[k] = rest[t[k]] + offset * normal[t[k]];
      const double v = signedTetVolume(p[0], p[1], p[2], p[3]);
      volume += v;
      smallest = std::min(smallest, v);
    }
    return std::pair{volume, smallest};
  };
  const auto [volume0, smallest0] = measure(0);
  double area = 0;
  for (const Triangle& f : boundary) {
    const Vec3d a = rest[f[0]];
    area += 0.5 * (rest[f[1]] - a).cross(rest[f[2]] - a).norm();
  }
  double offset = 0, volume = volume0;
  double step = (targetVolume - volume0) / area;
  for (int iteration = 0; iteration < 8 && std::abs(volume - targetVolume) > 1e-9 * targetVolume; ++iteration) {
    auto [trial, smallest] = measure(offset + step);
    while (smallest < 0.25 * smallest0 && std::abs(step) > 0) {  // keep every tet at least a quarter of its volume
      step *= 0.5;
      std::tie(trial, smallest) = measure(offset + step);
    }
    const double slope = (trial - volume) / step;
    offset += step;
    volume = trial;
    if (!(slope > 0)) break;
    step = (targetVolume - volume) / slope;
  }
  for (std::size_t v = 0; v < rest.size(); ++v) mesh.vertices[v] = (rest[v] + offset * normal[v]).cast<float>();
}

}  // namespace

Stuffing stuffIsosurface(const TriMesh& surface, const StuffingOptions& options) {
  const double cellSize = options.cellSize;
  const std::size_t maxLatticeVertices = options.maxLatticeVertices;
  if (!(cellSize > 0) || !std::isfinite(cellSize))
    throw Error(fmt::format("isosurface stuffing: the cell size must be positive (got {})", cellSize));
  validateTriMesh(surface);
  const SurfaceQuery query(surface);
  Box3d bounds;
  for (const Vec3& v : surface.vertices) bounds.extend(v.cast<double>());

  Stuffer s{query, {}, {}, {}, {}};
  Lattice& l = s.lattice;
  l.h = cellSize;
  // An odd margin keeps lattice planes off axis-aligned faces of the input.
  const double margin = 1.37 * cellSize;
  l.origin = bounds.min() - Vec3d::Constant(margin);
  const Vec3d cells = ((bounds.sizes() + Vec3d::Constant(2 * margin)) / cellSize).array().ceil();
  if ((cells.array() + 1).prod() * 2 > double(maxLatticeVertices))
    throw Error(fmt::format("isosurface stuffing: cell size {} needs a {}x{}x{} lattice, too fine for this surface",
                            cellSize, cells.x(), cells.y(), cells.z()));
  l.nx = int(cells.x());
  l.ny = int(cells.y());
  l.nz = int(cells.z());

  std::vector<Tet> lattice = latticeTets(l);
  s.classify();
  // Only tets with an inside vertex can contribute.
  std::erase_if(lattice, [&](const Tet& t) {
    return std::none_of(t.begin(), t.end(), [&](Index v) { return s.sign[v] == kInside; });
  });
  s.cutAndWarp(lattice);

  std::vector<Tet> tets;
  for (const Tet& t : lattice) {
    const bool anyInside = std::any_of(t.begin(), t.end(), [&](Index v) { return s.sign[v] == kInside; });
    const bool anyOutside = std::any_of(t.begin(), t.end(), [&](Index v) { return s.sign[v] == kOutside; });
    if (!anyInside && !anyOutside) {  // all four warped onto the surface: keep it if it lies inside
      Vec3d centre = Vec3d::Zero();
      for (Index v : t) centre += s.position[v] / 4.0;
      if (!query.inside(centre)) continue;
    }
    if (!anyInside && anyOutside) continue;
    if (anyOutside)
      s.fillCut(t, tets);
    else
      tets.push_back(t);
  }

  // Compact the used vertices, orient every tet positively and drop flat ones.
  TetMesh mesh;
  std::vector<Index> remap(s.position.size(), ~Index{0});
  for (Tet t : tets) {
    const Vec3d& a = s.position[t[0]];
    const double volume = (s.position[t[1]] - a).cross(s.position[t[2]] - a).dot(s.position[t[3]] - a) / 6;
    const double scale = cellSize * cellSize * cellSize;
    if (std::abs(volume) < 1e-9 * scale) continue;
    if (volume < 0) std::swap(t[2], t[3]);
    for (Index& v : t) {
      if (remap[v] == ~Index{0}) {
        remap[v] = static_cast<Index>(mesh.vertices.size());
        mesh.vertices.push_back(s.position[v].cast<float>());
      }
      v = remap[v];
    }
    mesh.tets.push_back(t);
  }
  Stuffing result;
  result.dropped = keepOnePiecePerShell(mesh, surface);
  if (options.preserveVolume && !mesh.tets.empty()) restoreVolume(mesh, enclosedVolume(surface));
  result.mesh = std::move(mesh);
  return result;
}

}  // namespace vrd
