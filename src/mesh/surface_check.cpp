#include "vrdeform/mesh/surface_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <numeric>

#include "mesh/one_based.h"
#include "mesh/triangle_intersection.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/bvh.h"

namespace vrd {
namespace {

constexpr Index kNone = ~Index{0};

// Union-find with path halving; the smaller id becomes the root.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), Index{0}); }
  Index find(Index x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<Index> parent_;
};

std::string plural(std::size_t n, const char* one, const char* many) {
  return fmt::format("{} {}", n, n == 1 ? one : many);
}

// The smallest `n` distinct ids, in order.
std::vector<Index> firstIds(std::vector<Index> ids, std::size_t n) {
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  if (ids.size() > n) ids.resize(n);
  return ids;
}

Vec3d point(const TriMesh& mesh, Index v) { return mesh.vertices[v].cast<double>(); }

Triangle3d corners(const TriMesh& mesh, const Triangle& t) {
  return {point(mesh, t[0]), point(mesh, t[1]), point(mesh, t[2])};
}

// Solid angle of triangle t seen from x (Van Oosterom and Strackee), for winding numbers.
double solidAngle(const Triangle3d& t, const Vec3d& x) {
  const Vec3d a = t[0] - x, b = t[1] - x, c = t[2] - x;
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double numerator = a.dot(b.cross(c));
  const double denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2 * std::atan2(numerator, denominator);
}

// What a face is fit for: topology needs valid distinct indices, geometry finite coordinates
// too, and the intersection test a non-zero area as well.
enum class FaceState : std::uint8_t { Good, Degenerate, NonFinite, RepeatedIndex, BadIndex };

bool hasTopology(FaceState s) { return s != FaceState::RepeatedIndex && s != FaceState::BadIndex; }
bool hasGeometry(FaceState s) { return s == FaceState::Good || s == FaceState::Degenerate; }

struct HalfEdge {
  std::uint64_t key;  ///< (smaller vertex << 32) | larger vertex
  Index face;
  Index from;
};

}  // namespace

const char* toString(SurfaceDefect defect) {
  switch (defect) {
    case SurfaceDefect::Empty:
      return "empty";
    case SurfaceDefect::NonFinite:
      return "non-finite or out-of-range coordinate";
    case SurfaceDefect::BadIndex:
      return "bad vertex index";
    case SurfaceDefect::DegenerateFace:
      return "degenerate face";
    case SurfaceDefect::NonManifoldEdge:
      return "non-manifold edge";
    case SurfaceDefect::NonManifoldVertex:
      return "non-manifold vertex";
    case SurfaceDefect::BoundaryEdge:
      return "boundary edge";
    case SurfaceDefect::InconsistentOrientation:
      return "inconsistent orientation";
    case SurfaceDefect::SelfIntersection:
      return "self-intersection";
    case SurfaceDefect::InwardOrientation:
      return "inward orientation";
  }
  return "unknown";
}

const SurfaceIssue* SurfaceReport::find(SurfaceDefect defect) const {
  for (const SurfaceIssue& issue : issues)
    if (issue.defect == defect) return &issue;
  return nullptr;
}

std::string SurfaceReport::summary() const {
  std::string text =
      fmt::format("{}, {}, {} ({} boundary), {}, area {:.6g}, volume {:.6g}: ", plural(vertices, "vertex", "vertices"),
                  plural(faces, "face", "faces"), plural(edges, "edge", "edges"), boundaryEdges,
                  plural(components, "component", "components"), area, volume);
  if (ok()) return text + "ok";
  text += plural(issues.size(), "issue", "issues");
  for (const SurfaceIssue& issue : issues) text += fmt::format("\n  {}: {}", toString(issue.defect), issue.message);
  return text;
}

double enclosedVolume(const TriMesh& mesh) {
  double sum = 0;
  for (const Triangle& t : mesh.triangles) {
    if (t[0] >= mesh.vertices.size() || t[1] >= mesh.vertices.size() || t[2] >= mesh.vertices.size()) continue;
    sum += point(mesh, t[0]).dot(point(mesh, t[1]).cross(point(mesh, t[2])));
  }
  return sum / 6;
}

SurfaceReport checkSurface(const TriMesh& mesh, const SurfaceCheckOptions& options) {
  SurfaceReport report;
  const std::size_t nv = mesh.vertices.size(), nf = mesh.triangles.size();
  report.vertices = nv;
  report.faces = nf;
  const std::size_t listed = std::max<std::size_t>(options.maxListed, 1);
  auto add = [&](SurfaceDefect defect, std::size_t count, std::vector<Index> ids, std::string message) {
    report.issues.push_back({defect, count, firstIds(std::move(ids), listed), std::move(message)});
  };

  if (nf == 0) {
    add(SurfaceDefect::Empty, 0, {}, fmt::format("surface has no faces ({})", plural(nv, "vertex", "vertices")));
    return report;
  }

  // Vertices and faces one by one. A coordinate beyond kMaxCoordinate is as unusable as a NaN: its
  // faces' areas and normals lose every digit (a float keeps 7), so it is reported as such
  // instead of as the degenerate faces it makes.
  constexpr float kMaxCoordinate = 1e15f;
  std::vector<char> finite(nv);
  std::vector<Index> nonFinite;
  for (std::size_t v = 0; v < nv; ++v)
    if (!(finite[v] = isFinite(mesh.vertices[v]) && mesh.vertices[v].cwiseAbs().maxCoeff() <= kMaxCoordinate))
      nonFinite.push_back(Index(v));

  std::vector<FaceState> state(nf, FaceState::Good);
  std::vector<Index> badIndex, degenerate;
  std::string badIndexDetail, degenerateDetail;
  for (std::size_t f = 0; f < nf; ++f) {
    const Triangle& t = mesh.triangles[f];
    const auto outside = std::find_if(t.begin(), t.end(), [&](Index v) { return v >= nv; });
    if (outside != t.end()) {
      state[f] = FaceState::BadIndex;
      if (badIndex.empty())
        badIndexDetail = fmt::format("face {} refers to vertex {}, but there are only {}", f + 1, oneBased(*outside),
                                     plural(nv, "vertex", "vertices"));
      badIndex.push_back(Index(f));
    } else if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      state[f] = FaceState::RepeatedIndex;
      if (degenerate.empty())
        degenerateDetail = fmt::format("face {} uses vertex {} twice ({})", f + 1, oneBased(t[1] == t[2] ? t[1] : t[0]),
                                       oneBasedList(t));
      degenerate.push_back(Index(f));
    } else if (!finite[t[0]] || !finite[t[1]] || !finite[t[2]]) {
      state[f] = FaceState::NonFinite;
    } else {
      const Triangle3d p = corners(mesh, t);
      const double twiceArea = (p[1] - p[0]).cross(p[2] - p[0]).norm();
      const double longest = std::max({(p[1] - p[0]).norm(), (p[2] - p[1]).norm(), (p[0] - p[2]).norm()});
      report.area += twiceArea / 2;
      if (!(twiceArea >= kDegenerateShape * longest * longest) || longest == 0) {
        state[f] = FaceState::Degenerate;
        if (degenerate.empty())
          degenerateDetail = fmt::format("face {} has zero area (vertices {} are collinear)", f + 1, oneBasedList(t));
        degenerate.push_back(Index(f));
      }
    }
  }

  if (!nonFinite.empty()) {
    std::vector<std::string> details;
    for (std::size_t k = 0; k < std::min(listed, nonFinite.size()); ++k) {
      const Index v = nonFinite[k];
      const Vec3& x = mesh.vertices[v];
      std::string usedBy = "unused";
      for (std::size_t f = 0; f < nf; ++f)
        if (state[f] == FaceState::NonFinite && std::count(mesh.triangles[f].begin(), mesh.triangles[f].end(), v)) {
          usedBy = fmt::format("in face {}", f + 1);
          break;
        }
      details.push_back(fmt::format("vertex {} = ({}, {}, {}) {}{}", oneBased(v), x.x(), x.y(), x.z(), usedBy,
                                    isFinite(x) ? fmt::format(", beyond +-{:g}", kMaxCoordinate) : ""));
    }
    add(SurfaceDefect::NonFinite, nonFinite.size(), nonFinite,
        nonFinite.size() == 1
            ? fmt::format("a vertex has a non-finite or out-of-range coordinate: {}", details[0])
            : fmt::format("{} vertices have non-finite or out-of-range coordinates: {}{}", nonFinite.size(),
                          fmt::join(details, "; "), nonFinite.size() > listed ? "; ..." : ""));
  }
  if (!badIndex.empty())
    add(SurfaceDefect::BadIndex, badIndex.size(), badIndex,
        badIndex.size() == 1 ? badIndexDetail
                             : fmt::format("{} faces have out-of-range vertex indices ({}; first faces {})",
                                           badIndex.size(), badIndexDetail, oneBasedList(firstIds(badIndex, listed))));
  if (!degenerate.empty())
    add(SurfaceDefect::DegenerateFace, degenerate.size(), degenerate,
        degenerate.size() == 1 ? degenerateDetail
                               : fmt::format("{} degenerate faces ({}; first faces {})", degenerate.size(),
                                             degenerateDetail, oneBasedList(firstIds(degenerate, listed))));

  // Edges: half-edges sorted by undirected edge, then face.
  std::vector<HalfEdge> halfEdges;
  halfEdges.reserve(3 * nf);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!hasTopology(state[f])) continue;
    const Triangle& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const Index a = t[k], b = t[(k + 1) % 3];
      halfEdges.push_back({(std::uint64_t(std::min(a, b)) << 32) | std::max(a, b), Index(f), a});
    }
  }
  std::sort(halfEdges.begin(), halfEdges.end(),
            [](const HalfEdge& x, const HalfEdge& y) { return x.key != y.key ? x.key < y.key : x.face < y.face; });

  DisjointSets faceSets(nf);
  DisjointSets fans(3 * nf);  // one element per face corner, joined across manifold edges
  auto corner = [&](Index f, Index v) {
    const Triangle& t = mesh.triangles[f];
    return 3 * f + (t[0] == v ? 0 : t[1] == v ? 1 : 2);
  };
  struct Link {
    Index f, g;
    bool flipped;  ///< both faces traverse the edge the same way
  };
  std::vector<Link> links;
  std::vector<char> onNonManifoldEdge(nv, 0);
  std::vector<Index> boundaryFaces, nonManifoldFaces;
  std::size_t nonManifoldEdges = 0, inconsistentEdges = 0;
  std::string nonManifoldDetail, inconsistentDetail;
  for (std::size_t i = 0; i < halfEdges.size();) {
    std::size_t j = i + 1;
    while (j < halfEdges.size() && halfEdges[j].key == halfEdges[i].key) ++j;
    const Index lo = Index(halfEdges[i].key >> 32), hi = Index(halfEdges[i].key & 0xffffffffu);
    ++report.edges;
    for (std::size_t m = i + 1; m < j; ++m) faceSets.unite(halfEdges[i].face, halfEdges[m].face);
    if (j - i == 1) {
      ++report.boundaryEdges;
      boundaryFaces.push_back(halfEdges[i].face);
    } else if (j - i == 2) {
      const Index f = halfEdges[i].face, g = halfEdges[i + 1].face;
      const bool flipped = halfEdges[i].from == halfEdges[i + 1].from;
      if (flipped && inconsistentEdges++ == 0)
        inconsistentDetail =
            fmt::format("edge {}-{} by faces {} and {}", oneBased(lo), oneBased(hi), oneBased(f), oneBased(g));
      links.push_back({f, g, flipped});
      fans.unite(corner(f, lo), corner(g, lo));
      fans.unite(corner(f, hi), corner(g, hi));
    } else {
      std::vector<Index> sharing;
      for (std::size_t m = i; m < j; ++m) sharing.push_back(halfEdges[m].face);
      if (nonManifoldEdges++ == 0)
        nonManifoldDetail = fmt::format("edge {}-{} is shared by {} faces: {}", oneBased(lo), oneBased(hi),
                                        sharing.size(), oneBasedList(sharing));
      nonManifoldFaces.insert(nonManifoldFaces.end(), sharing.begin(), sharing.end());
      onNonManifoldEdge[lo] = onNonManifoldEdge[hi] = 1;
    }
    i = j;
  }
  if (nonManifoldEdges > 0)
    add(SurfaceDefect::NonManifoldEdge, nonManifoldEdges, nonManifoldFaces,
        fmt::format("{} ({})", plural(nonManifoldEdges, "non-manifold edge", "non-manifold edges"), nonManifoldDetail));

  // A vertex whose corners fall into several fans pinches the surface (vertices on non-manifold
  // edges are already reported).
  {
    std::vector<Index> fanOf(nv, kNone), fanFace(nv, kNone), pinchedFaces;
    std::vector<char> pinched(nv, 0);
    std::size_t count = 0;
    std::string detail;
    for (std::size_t f = 0; f < nf; ++f) {
      if (!hasTopology(state[f])) continue;
      for (int k = 0; k < 3; ++k) {
        const Index v = mesh.triangles[f][k];
        if (onNonManifoldEdge[v]) continue;
        const Index fan = fans.find(Index(3 * f + k));
        if (fanOf[v] == kNone) {
          fanOf[v] = fan;
          fanFace[v] = Index(f);
        } else if (fanOf[v] != fan && !pinched[v]) {
          pinched[v] = 1;
          if (count++ == 0)
            detail = fmt::format("faces {} and {} meet only at vertex {}, in separate fans", oneBased(fanFace[v]),
                                 f + 1, oneBased(v));
          pinchedFaces.push_back(fanFace[v]);
          pinchedFaces.push_back(Index(f));
        }
      }
    }
    if (count > 0)
      add(SurfaceDefect::NonManifoldVertex, count, pinchedFaces,
          fmt::format("{} ({})", plural(count, "non-manifold vertex", "non-manifold vertices"), detail));
  }

  if (report.boundaryEdges > 0 && options.requireClosed)
    add(SurfaceDefect::BoundaryEdge, report.boundaryEdges, boundaryFaces,
        fmt::format("surface is open: {} (first faces {})",
                    plural(report.boundaryEdges, "boundary edge", "boundary edges"),
                    oneBasedList(firstIds(boundaryFaces, listed))));

  if (inconsistentEdges > 0) {
    // Give each face a flip relative to the first face of its patch; the minority of each patch
    // are the faces to reverse.
    std::vector<std::vector<std::pair<Index, bool>>> neighbours(nf);
    for (const Link& l : links) {
      neighbours[l.f].push_back({l.g, l.flipped});
      neighbours[l.g].push_back({l.f, l.flipped});
    }
    std::vector<signed char> flip(nf, -1);
    std::vector<Index> toReverse, queue, kept, reversed;
    bool orientable = true;
    for (std::size_t seed = 0; seed < nf; ++seed) {
      if (!hasTopology(state[seed]) || flip[seed] >= 0) continue;
      flip[seed] = 0;
      queue.assign(1, Index(seed));
      kept.clear();
      reversed.clear();
      for (std::size_t q = 0; q < queue.size(); ++q) {
        const Index f = queue[q];
        (flip[f] ? reversed : kept).push_back(f);
        for (const auto& [g, flipped] : neighbours[f]) {
          const auto want = static_cast<signed char>(flip[f] ^ flipped);
          if (flip[g] < 0) {
            flip[g] = want;
            queue.push_back(g);
          } else if (flip[g] != want) {
            orientable = false;
          }
        }
      }
      const std::vector<Index>& minority = reversed.size() <= kept.size() ? reversed : kept;
      toReverse.insert(toReverse.end(), minority.begin(), minority.end());
    }
    add(SurfaceDefect::InconsistentOrientation, inconsistentEdges, toReverse,
        fmt::format("orientation is inconsistent: {} traversed in the same direction by both faces ({}); {}",
                    plural(inconsistentEdges, "edge is", "edges are"), inconsistentDetail,
                    !orientable             ? std::string("the surface is not orientable")
                    : toReverse.size() == 1 ? fmt::format("reverse face {}", oneBased(toReverse[0]))
                                            : fmt::format("reverse {} faces ({}{})", toReverse.size(),
                                                          oneBasedList(firstIds(toReverse, listed)),
                                                          toReverse.size() > listed ? ", ..." : "")));
  }

  // Components, their volumes and a face of each.
  std::vector<Index> component(nf, kNone), componentFace;
  std::vector<double> componentVolume;
  {
    std::vector<Index> idOfRoot(nf, kNone);
    for (std::size_t f = 0; f < nf; ++f) {
      if (!hasTopology(state[f])) continue;
      const Index root = faceSets.find(Index(f));
      if (idOfRoot[root] == kNone) {
        idOfRoot[root] = Index(componentFace.size());
        componentFace.push_back(Index(f));
        componentVolume.push_back(0);
      }
      component[f] = idOfRoot[root];
      if (!hasGeometry(state[f])) continue;
      const Triangle3d p = corners(mesh, mesh.triangles[f]);
      componentVolume[component[f]] += p[0].dot(p[1].cross(p[2]));  // six times the volume until below
    }
    for (double& v : componentVolume) v /= 6;
    report.components = componentFace.size();
    report.volume = std::accumulate(componentVolume.begin(), componentVolume.end(), 0.0);
  }

  if (options.checkSelfIntersection) {
    std::vector<Index> faces;
    std::vector<Triangle3d> triangles;
    std::vector<double> tolerance;
    std::vector<Box3d> boxes;
    for (std::size_t f = 0; f < nf; ++f) {
      if (state[f] != FaceState::Good) continue;
      const Triangle3d p = corners(mesh, mesh.triangles[f]);
      const double tol = intersectionTolerance(p, p);
      Box3d box;
      for (const Vec3d& x : p) box.extend(x);
      faces.push_back(Index(f));
      triangles.push_back(p);
      tolerance.push_back(tol);
      boxes.emplace_back(box.min() - Vec3d::Constant(tol), box.max() + Vec3d::Constant(tol));
    }
    const Bvh bvh(boxes);
    std::size_t pairs = 0;
    std::vector<std::string> examples;
    std::vector<Index> involved;
    for (Index i = 0; i < faces.size(); ++i) {
      bvh.overlapping(boxes[i], [&](Index j) {
        if (j <= i) return;
        if (!facesIntersect(triangles[i], mesh.triangles[faces[i]], triangles[j], mesh.triangles[faces[j]],
                            std::max(tolerance[i], tolerance[j])))
          return;
        if (pairs++ < listed) {
          examples.push_back(fmt::format("{} and {}", oneBased(faces[i]), oneBased(faces[j])));
          involved.push_back(faces[i]);
          involved.push_back(faces[j]);
        }
      });
    }
    if (pairs > 0)
      add(SurfaceDefect::SelfIntersection, pairs, involved,
          pairs == 1 ? fmt::format("faces {} intersect", examples[0])
                     : fmt::format("{} pairs of faces intersect (faces {}{})", pairs, fmt::join(examples, "; "),
                                   pairs > listed ? "; ..." : ""));
  }

  // Inside out: a closed, consistent component with negative volume that is not a cavity, i.e.
  // not enclosed by the other components (winding number of one of its points about them).
  if (report.boundaryEdges == 0 && nonManifoldEdges == 0 && inconsistentEdges == 0) {
    auto enclosedByOthers = [&](Index c) {
      const Triangle3d p = corners(mesh, mesh.triangles[componentFace[c]]);
      const Vec3d x = (p[0] + p[1] + p[2]) / 3;
      double angle = 0;
      for (std::size_t f = 0; f < nf; ++f)
        if (hasGeometry(state[f]) && component[f] != c) angle += solidAngle(corners(mesh, mesh.triangles[f]), x);
      return std::abs(angle) > 2 * std::numbers::pi;  // winding number above 1/2
    };
    std::vector<Index> inward;
    for (Index c = 0; c < componentFace.size(); ++c)
      if (componentVolume[c] < 0 && (componentFace.size() == 1 || !enclosedByOthers(c))) inward.push_back(c);
    if (!inward.empty()) {
      std::vector<Index> faces;
      for (Index c : inward) faces.push_back(componentFace[c]);
      add(SurfaceDefect::InwardOrientation, inward.size(), faces,
          componentFace.size() == 1
              ? fmt::format("surface is inside out: enclosed volume {:.6g} is negative (reverse every face)",
                            componentVolume[0])
              : fmt::format("{} of {} components are inside out (the component of face {} encloses volume {:.6g})",
                            inward.size(), componentFace.size(), oneBased(componentFace[inward[0]]),
                            componentVolume[inward[0]]));
    }
  }
  return report;
}

void requireClosedSurface(const TriMesh& mesh) {
  const SurfaceReport report = checkSurface(mesh);
  if (report.ok()) return;
  std::vector<std::string> messages;
  for (const SurfaceIssue& issue : report.issues) messages.push_back(issue.message);
  throw Error(fmt::format("not a clean closed surface: {}", fmt::join(messages, "; ")));
}

}  // namespace vrd
