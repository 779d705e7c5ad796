#pragma once
// A bounding-volume hierarchy of axis-aligned boxes, for the mesh pipeline's spatial queries:
// triangle-pair candidates (self-intersection), closest surface point (meshing, inside tests)
// and the tet that contains a point (render-mesh embedding). Built once, read-only afterwards.

#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

using Box3d = Eigen::AlignedBox<double, 3>;

class Bvh {
 public:
  Bvh() = default;
  /// Builds the tree over items 0..boxes.size()-1 by median splits along the widest centroid axis.
  explicit Bvh(std::span<const Box3d> boxes);

  bool empty() const { return nodes_.empty(); }

  /// Calls visit(item) for every item whose box overlaps `box`.
  template <typename Visit>
  void overlapping(const Box3d& box, Visit&& visit) const {
    if (nodes_.empty()) return;
    Index stack[kMaxDepth];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!node.box.intersects(box)) continue;
      if (node.count > 0) {
        for (Index k = node.first; k < node.first + node.count; ++k)
          if (itemBoxes_[items_[k]].intersects(box)) visit(items_[k]);
      } else {
        stack[top++] = node.first;  // right child
        stack[top++] = static_cast<Index>(&node - nodes_.data()) + 1;
      }
    }
  }

  /// The item minimising distanceSq(item) (a squared distance from some query point that its box
  /// bounds from below: boxDistanceSq(box) <= distanceSq(item)), and that distance. Branch and bound.
  /// Returns {-1 as Index, inf} for an empty tree.
  template <typename BoxDistanceSq, typename ItemDistanceSq>
  std::pair<Index, double> nearest(BoxDistanceSq&& boxDistanceSq, ItemDistanceSq&& distanceSq) const {
    std::pair<Index, double> best{~Index{0}, std::numeric_limits<double>::infinity()};
    if (nodes_.empty()) return best;
    std::pair<Index, double> stack[kMaxDepth];
    int top = 0;
    stack[top++] = {0, boxDistanceSq(nodes_[0].box)};
    while (top > 0) {
      const auto [index, bound] = stack[--top];
      if (bound >= best.second) continue;
      const Node& node = nodes_[index];
      if (node.count > 0) {
        for (Index k = node.first; k < node.first + node.count; ++k) {
          const double d = distanceSq(items_[k]);
          if (d < best.second) best = {items_[k], d};
        }
        continue;
      }
      std::pair<Index, double> left{index + 1, boxDistanceSq(nodes_[index + 1].box)};
      std::pair<Index, double> right{node.first, boxDistanceSq(nodes_[node.first].box)};
      if (left.second < right.second) std::swap(left, right);  // visit the nearer child first
      stack[top++] = left;
      stack[top++] = right;
    }
    return best;
  }

  /// Nearest item to point p, with distanceSq(item) the item's squared distance to p.
  template <typename ItemDistanceSq>
  std::pair<Index, double> nearestTo(const Vec3d& p, ItemDistanceSq&& distanceSq) const {
    return nearest([&](const Box3d& b) { return b.squaredExteriorDistance(p); }, distanceSq);
  }

 private:
  struct Node {
    Box3d box;
    Index first = 0;  ///< leaf: first entry in items_; inner node: right child (left is the next node)
    Index count = 0;  ///< items in a leaf, 0 for an inner node
  };
  static constexpr int kMaxDepth = 128;
  Index build(Index begin, Index end, std::vector<Vec3d>& centres, int depth);

  std::vector<Node> nodes_;
  std::vector<Index> items_;
  std::vector<Box3d> itemBoxes_;
};

/// The bounding box of a triangle or tet given by its vertex indices.
template <typename Element>
Box3d elementBox(const std::vector<Vec3>& vertices, const Element& element) {
  Box3d box;
  for (Index v : element) box.extend(vertices[v].cast<double>());
  return box;
}

}  // namespace vrd
