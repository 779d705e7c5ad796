#include "vrdeform/mesh/bvh.h"

#include <algorithm>
#include <numeric>

namespace vrd {

namespace {
constexpr Index kLeafSize = 4;
}

Bvh::Bvh(std::span<const Box3d> boxes) : items_(boxes.size()), itemBoxes_(boxes.begin(), boxes.end()) {
  if (boxes.empty()) return;
  std::iota(items_.begin(), items_.end(), Index{0});
  std::vector<Vec3d> centres(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) centres[i] = boxes[i].center();
  nodes_.reserve(2 * boxes.size() / kLeafSize + 1);
  build(0, static_cast<Index>(items_.size()), centres, 0);
}

Index Bvh::build(Index begin, Index end, std::vector<Vec3d>& centres, int depth) {
  const Index index = static_cast<Index>(nodes_.size());
  nodes_.emplace_back();
  Box3d box, centreBox;
  for (Index k = begin; k < end; ++k) {
    box.extend(itemBoxes_[items_[k]]);
    centreBox.extend(centres[items_[k]]);
  }
  nodes_[index].box = box;
  // Median splits give depth log2(n / kLeafSize); the depth cap only guards the query stacks.
  if (end - begin <= kLeafSize || depth + 2 >= kMaxDepth / 2) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  centreBox.sizes().maxCoeff(&axis);
  const Index mid = begin + (end - begin) / 2;
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                   [&](Index a, Index b) { return centres[a][axis] < centres[b][axis]; });
  build(begin, mid, centres, depth + 1);
  const Index right = build(mid, end, centres, depth + 1);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

}  // namespace vrd
