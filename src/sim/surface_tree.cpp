#include "vrdeform/sim/surface_tree.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace vrd {
namespace {

constexpr Index kLeafSize = 4;
constexpr int kCutDepth = 3;                           // up to 8 parts: work for a few threads, little lost at the cut
const NormalCone kSphere{Vec3::UnitZ(), -1.0f, 0.0f};  // holds every direction

}  // namespace

NormalCone coneAbout(const Vec3& axis, std::span<const Index> triangles, std::span<const Vec3> startNormals,
                     std::span<const Vec3> endNormals) {
  float cosine = 1.0f;
  for (Index t : triangles)
    for (const Vec3* n : {&startNormals[t], &endNormals[t]}) {
      const float d = axis.dot(*n);
      if (!(d >= cosine)) cosine = d;  // also a NaN
    }
  if (!(cosine > -1.0f && axis.allFinite())) return kSphere;
  return {axis, cosine, std::sqrt(1.0f - cosine * cosine)};
}

NormalCone enclosing(const Vec3& axis, const NormalCone& a, const NormalCone& b) {
  NormalCone cone{axis, 1.0f, 0.0f};
  for (const NormalCone* c : {&a, &b}) {
    const float cosine = axis.dot(c->axis), sine = axis.cross(c->axis).norm();
    const float sum = sine * c->cos + cosine * c->sin;  // the sine of the angle from the axis to c's rim
    if (!(sum >= 0.0f)) return kSphere;                 // past 180 degrees
    const float rim = cosine * c->cos - sine * c->sin;
    if (rim < cone.cos) cone = {axis, rim, sum};
  }
  return cone;
}

void SurfaceTree::build(std::span<const Triangle> triangles, std::span<const Vec3> rest) {
  nodes_.clear();
  parts_.clear();
  items_.resize(triangles.size());
  boxes_.resize(triangles.size());
  if (triangles.empty()) return;
  std::vector<Vec3> centres;
  for (const Triangle& t : triangles) centres.push_back((rest[t[0]] + rest[t[1]] + rest[t[2]]) / 3.0f);
  std::iota(items_.begin(), items_.end(), Index{0});
  nodes_.reserve(2 * triangles.size() / kLeafSize + 1);
  build(0, Index(items_.size()), centres, 0);
  // Each leaf's triangles and those around their corners.
  Index corners = 0;
  for (const Triangle& t : triangles) corners = std::max({corners, t[0] + 1, t[1] + 1, t[2] + 1});
  std::vector<std::vector<Index>> atCorner(corners);
  for (Index t = 0; t < triangles.size(); ++t)
    for (Index c : triangles[t]) atCorner[c].push_back(t);
  aroundStart_.assign(1, 0);
  around_.clear();
  for (const Node& node : nodes_) {
    const auto first = around_.end() - around_.begin();
    for (Index k = node.first; k < node.first + node.count; ++k)
      for (Index c : triangles[items_[k]]) around_.insert(around_.end(), atCorner[c].begin(), atCorner[c].end());
    std::sort(around_.begin() + first, around_.end());
    around_.erase(std::unique(around_.begin() + first, around_.end()), around_.end());
    aroundStart_.push_back(Index(around_.size()));
  }
}

Index SurfaceTree::build(Index begin, Index end, std::span<const Vec3> centres, int depth) {
  const Index index = Index(nodes_.size());
  nodes_.emplace_back();
  Box3f spread;
  for (Index k = begin; k < end; ++k) spread.extend(centres[items_[k]]);
  // Median splits give depth log2(n / kLeafSize); the cap only keeps the recursion shallow.
  const auto part = [&] { parts_.push_back({index, Index(nodes_.size()), begin, end}); };
  if (end - begin <= kLeafSize || depth >= 48) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    if (depth <= kCutDepth) part();
    return index;
  }
  int axis = 0;
  spread.sizes().maxCoeff(&axis);
  const Index mid = begin + (end - begin) / 2;
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                   [&](Index a, Index b) { return centres[a][axis] < centres[b][axis]; });
  build(begin, mid, centres, depth + 1);
  nodes_[index].first = build(mid, end, centres, depth + 1);
  if (depth == kCutDepth) part();
  return index;
}

// Children come after their parent, so one backward pass sees both children of a node before it.
void SurfaceTree::refitPart(std::size_t part, const SurfaceFrame& frame) {
  const Part& p = parts_[part];
  const auto [boxes, startNormals, endNormals, moving] = frame;
  for (Index k = p.item; k < p.itemEnd; ++k) boxes_[k] = boxes[items_[k]];
  for (Index n = p.nodeEnd; n-- > p.node;) {
    Node& node = nodes_[n];
    if (node.count == 0) {
      const Node &left = nodes_[n + 1], &right = nodes_[node.first];
      node.box = left.box.merged(right.box);
      node.still = left.still && right.still;
      const Vec3 sum = left.cone.axis + right.cone.axis;
      node.cone = startNormals.empty() || !(sum.squaredNorm() > 1e-12f)
                      ? kSphere
                      : enclosing(sum.normalized(), left.cone, right.cone);
      continue;
    }
    node.box = boxes_[node.first];
    node.still = true;
    for (Index k = node.first; k < node.first + node.count; ++k) {
      node.box.extend(boxes_[k]);
      node.still = node.still && !moving.empty() && !moving[items_[k]];
    }
    if (startNormals.empty()) {
      node.cone = kSphere;
      continue;
    }
    // About the normals' mean direction.
    const std::span<const Index> around(around_.data() + aroundStart_[n], around_.data() + aroundStart_[n + 1]);
    Vec3 sum = Vec3::Zero();
    for (Index t : around) sum += startNormals[t] + endNormals[t];
    node.cone = sum.norm() > 1e-6f ? coneAbout(sum.normalized(), around, startNormals, endNormals) : kSphere;
  }
}

}  // namespace vrd
