#include "vrdeform/sim/surface_tree.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace vrd {
namespace {

constexpr Index kLeafSize = 4;
constexpr float kPi = std::numbers::pi_v<float>;
const NormalCone kSphere{Vec3::UnitZ(), -1.0f, 0.0f};  // holds every direction

float angleBetween(const Vec3& a, const Vec3& b) { return std::acos(std::clamp(a.dot(b), -1.0f, 1.0f)); }

}  // namespace

NormalCone coneOf(std::span<const Vec3> normals) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& n : normals) {
    if (!(std::abs(n.squaredNorm() - 1.0f) < 1e-3f)) return kSphere;  // a degenerate triangle's
    sum += n;
  }
  const float length = sum.norm();
  if (!(length > 1e-6f)) return kSphere;
  const Vec3 axis = sum / length;
  float cosine = 1.0f;
  for (const Vec3& n : normals) cosine = std::min(cosine, axis.dot(n));
  cosine = std::max(cosine, -1.0f);
  return {axis, cosine, std::sqrt(1.0f - cosine * cosine)};
}

NormalCone merge(const NormalCone& a, const NormalCone& b) {
  const float between = angleBetween(a.axis, b.axis), angleA = std::acos(a.cos), angleB = std::acos(b.cos);
  if (between + angleB <= angleA) return a;
  if (between + angleA <= angleB) return b;
  const float angle = 0.5f * (between + angleA + angleB);
  if (!(angle < kPi)) return kSphere;
  // The axis turned from a's towards b's by (angle - angleA), in their plane.
  const float turn = angle - angleA;
  const Vec3 axis =
      between < 1e-6f
          ? a.axis
          : Vec3((std::sin(between - turn) * a.axis + std::sin(turn) * b.axis) / std::sin(between)).normalized();
  return {axis, std::cos(angle), std::sin(angle)};
}

void SurfaceTree::build(std::span<const Triangle> triangles, std::span<const Vec3> rest) {
  nodes_.clear();
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
  if (end - begin <= kLeafSize || depth >= 48) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  spread.sizes().maxCoeff(&axis);
  const Index mid = begin + (end - begin) / 2;
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                   [&](Index a, Index b) { return centres[a][axis] < centres[b][axis]; });
  build(begin, mid, centres, depth + 1);
  nodes_[index].first = build(mid, end, centres, depth + 1);
  return index;
}

// Children come after their parent, so one backward pass sees both children of a node before it.
void SurfaceTree::refit(std::span<const Box3f> boxes, std::span<const Vec3> startNormals,
                        std::span<const Vec3> endNormals) {
  for (std::size_t k = 0; k < items_.size(); ++k) boxes_[k] = boxes[items_[k]];
  for (std::size_t n = nodes_.size(); n-- > 0;) {
    Node& node = nodes_[n];
    if (node.count == 0) {
      const Node &left = nodes_[n + 1], &right = nodes_[node.first];
      node.box = left.box.merged(right.box);
      node.cone = startNormals.empty() ? kSphere : merge(left.cone, right.cone);
      continue;
    }
    node.box = boxes_[node.first];
    for (Index k = node.first; k < node.first + node.count; ++k) node.box.extend(boxes_[k]);
    scratch_.clear();
    for (Index k = aroundStart_[n]; k < aroundStart_[n + 1] && !startNormals.empty(); ++k) {
      scratch_.push_back(startNormals[around_[k]]);
      scratch_.push_back(endNormals[around_[k]]);
    }
    node.cone = coneOf(scratch_);
  }
}

}  // namespace vrd
