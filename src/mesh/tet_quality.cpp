#include "vrdeform/mesh/tet_quality.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "vrdeform/mesh/surface_check.h"

namespace vrd {
namespace {

constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

// Interior angle at edge ab between the faces abc and abd: the angle between c and d seen along
// ab. atan2 keeps it accurate near 0 and 180 degrees, where acos is not.
double dihedralDeg(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const Vec3d e = (b - a).normalized();
  const Vec3d u = (c - a) - e * e.dot(c - a), w = (d - a) - e * e.dot(d - a);
  return std::atan2(u.cross(w).norm(), u.dot(w)) * (180 / std::numbers::pi);
}

}  // namespace

TetQuality measureTetQuality(const TetMesh& mesh, const TriMesh* surface) {
  TetQuality q;
  const std::size_t nv = mesh.vertices.size();
  q.vertices = nv;
  q.tets = mesh.tets.size();

  std::vector<char> used(nv, 0);
  std::vector<std::array<Index, 3>> faces;
  faces.reserve(4 * mesh.tets.size());
  double minAngle = std::numeric_limits<double>::infinity(), maxAngle = -minAngle;
  double minRatio = minAngle, maxRatio = maxAngle, sumRatio = 0;
  std::size_t measured = 0;

  for (const Tet& tet : mesh.tets) {
    bool valid = std::all_of(tet.begin(), tet.end(), [&](Index v) { return v < nv && isFinite(mesh.vertices[v]); });
    for (int i = 0; valid && i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) valid = valid && tet[i] != tet[j];
    if (!valid) {
      ++q.invalid;
      continue;
    }
    for (Index v : tet) used[v] = 1;
    for (int skip = 0; skip < 4; ++skip) {
      std::array<Index, 3> face;
      for (int k = 0, n = 0; k < 4; ++k)
        if (k != skip) face[n++] = tet[k];
      std::sort(face.begin(), face.end());
      faces.push_back(face);
    }

    Vec3d p[4];
    for (int k = 0; k < 4; ++k) p[k] = mesh.vertices[tet[k]].cast<double>();
    const Vec3d a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const double sixVolume = a.dot(b.cross(c));
    q.volume += sixVolume / 6;
    double shortest = std::numeric_limits<double>::infinity(), longest = 0;
    for (const auto& [i, j] : kEdges) {
      const double l = (p[i] - p[j]).norm();
      shortest = std::min(shortest, l);
      longest = std::max(longest, l);
    }
    if (!(std::abs(sixVolume) >= kDegenerateShape * longest * longest * longest)) {
      ++q.degenerate;
      continue;
    }
    if (sixVolume < 0) ++q.inverted;

    for (const auto& [i, j] : kEdges) {
      // The two vertices off the edge.
      int others[2], n = 0;
      for (int m = 0; m < 4; ++m)
        if (m != i && m != j) others[n++] = m;
      const double angle = dihedralDeg(p[i], p[j], p[others[0]], p[others[1]]);
      minAngle = std::min(minAngle, angle);
      maxAngle = std::max(maxAngle, angle);
      ++q.dihedralHistogram[std::min<std::size_t>(std::size_t(angle / 10), q.dihedralHistogram.size() - 1)];
    }
    // Circumcentre offset from p0: (|a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b)) / (2 a.(b x c)).
    const Vec3d centre =
        (a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b)) / (2 * sixVolume);
    const double ratio = centre.norm() / shortest;
    minRatio = std::min(minRatio, ratio);
    maxRatio = std::max(maxRatio, ratio);
    sumRatio += ratio;
    ++measured;
  }

  if (measured > 0) {
    q.minDihedralDeg = minAngle;
    q.maxDihedralDeg = maxAngle;
    q.minRadiusEdge = minRatio;
    q.maxRadiusEdge = maxRatio;
    q.meanRadiusEdge = sumRatio / double(measured);
  }
  q.unusedVertices = std::size_t(std::count(used.begin(), used.end(), 0));

  std::sort(faces.begin(), faces.end());
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j] == faces[i]) ++j;
    if (j - i == 1) ++q.boundaryFaces;
    if (j - i > 2) ++q.nonManifoldFaces;
    i = j;
  }

  if (surface) {
    q.surfaceVolume = enclosedVolume(*surface);
    if (*q.surfaceVolume != 0) q.volumeError = (q.volume - *q.surfaceVolume) / std::abs(*q.surfaceVolume);
  }
  return q;
}

std::string TetQuality::table() const {
  std::string text = fmt::format(
      "tet mesh quality\n"
      "  vertices           {} ({} unused)\n"
      "  tets               {} ({} inverted, {} degenerate, {} invalid)\n"
      "  boundary faces     {} ({} shared by more than two tets)\n"
      "  dihedral angle     {:.2f} .. {:.2f} deg (regular tet 70.53)\n"
      "  radius-edge ratio  {:.3f} .. {:.3f}, mean {:.3f} (regular tet 0.612)\n"
      "  volume             {:.6g}\n",
      vertices, unusedVertices, tets, inverted, degenerate, invalid, boundaryFaces, nonManifoldFaces, minDihedralDeg,
      maxDihedralDeg, minRadiusEdge, maxRadiusEdge, meanRadiusEdge, volume);
  if (surfaceVolume) {
    text += fmt::format("  surface volume     {:.6g}", *surfaceVolume);
    if (volumeError) text += fmt::format(" (tets differ by {:+.3f}%)", 100 * *volumeError);
    text += "\n";
  }
  std::size_t peak = 0;
  for (std::size_t n : dihedralHistogram) peak = std::max(peak, n);
  if (peak == 0) return text;
  text += "  dihedral angles (deg)\n";
  for (std::size_t bin = 0; bin < dihedralHistogram.size(); ++bin) {
    if (dihedralHistogram[bin] == 0) continue;
    const std::size_t width = (dihedralHistogram[bin] * 40 + peak - 1) / peak;
    text += fmt::format("    {:3}-{:<3} {:>8} {}\n", 10 * bin, 10 * bin + 10, dihedralHistogram[bin],
                        std::string(width, '#'));
  }
  return text;
}

}  // namespace vrd
