#include "vrdeform/mesh/vertex_normals.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "vrdeform/error.h"

namespace vrd {

void computeVertexNormals(std::span<const Triangle> triangles, std::span<const Vec3> positions,
                          std::span<Vec3> outNormals) {
  if (outNormals.size() != positions.size())
    throw Error(fmt::format("{} normals requested for {} positions", outNormals.size(), positions.size()));
  std::vector<Vec3d> sums(positions.size(), Vec3d::Zero());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    const Index largest = std::max({tri[0], tri[1], tri[2]});
    if (largest >= positions.size())
      throw Error(
          fmt::format("triangle {} refers to vertex {}, but there are only {} vertices", t, largest, positions.size()));
    const Vec3d a = positions[tri[0]].cast<double>();
    // |(b - a) x (c - a)| is twice the area: the area weighting comes for free.
    const Vec3d n = (positions[tri[1]].cast<double>() - a).cross(positions[tri[2]].cast<double>() - a);
    for (Index v : tri) sums[v] += n;
  }
  for (std::size_t v = 0; v < sums.size(); ++v) {
    const double length = sums[v].norm();
    outNormals[v] = length > 0 && std::isfinite(length) ? Vec3((sums[v] / length).cast<float>()) : Vec3::Zero();
  }
}

}  // namespace vrd
