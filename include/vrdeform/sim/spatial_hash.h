#pragma once
// A uniform grid of cubic cells hashed into a table (Teschner et al. 2003), rebuilt every substep
// for the broad phase of body contact: building it is linear in the items, whatever moved.

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

using Box3f = Eigen::AlignedBox<float, 3>;

class SpatialHash {
 public:
  /// Puts item k in every cell its box boxes[k] covers. A box that covers more than kMostCells
  /// cells (or is not finite, or lies beyond the grid's integer range) goes on a list every query visits.
  void build(std::span<const Box3f> boxes, float cellSize);

  /// Calls visit(item) for the items in the cells `box` covers and those on the list: an item may
  /// come more than once, and hash collisions bring items from elsewhere, so the caller checks boxes.
  template <typename Visit>
  void query(const Box3f& box, Visit&& visit) const {
    for (Index item : oversized_) visit(item);
    Cells c;
    if (start_.empty() || !cellsOf(box, c)) return;
    for (std::int64_t x = c.lo[0]; x <= c.hi[0]; ++x)
      for (std::int64_t y = c.lo[1]; y <= c.hi[1]; ++y)
        for (std::int64_t z = c.lo[2]; z <= c.hi[2]; ++z) {
          const std::size_t s = slot(x, y, z);
          for (Index k = start_[s]; k < start_[s + 1]; ++k) visit(items_[k]);
        }
  }

  static constexpr std::int64_t kMostCells = 512;

 private:
  struct Cells {
    std::int64_t lo[3], hi[3];
  };
  bool cellsOf(const Box3f& box, Cells& out) const;  // false: not finite or beyond the grid
  std::size_t slot(std::int64_t x, std::int64_t y, std::int64_t z) const {
    const auto h = std::uint64_t(x) * 73856093u ^ std::uint64_t(y) * 19349663u ^ std::uint64_t(z) * 83492791u;
    return std::size_t(h & mask_);
  }

  float invCell_ = 1.0f;
  std::uint64_t mask_ = 0;
  std::vector<Index> start_;  // the items of slot s: items_[start_[s], start_[s + 1])
  std::vector<Index> items_;
  std::vector<Index> oversized_;
  std::vector<Index> fill_;  // build's scratch
  std::vector<Cells> cells_;
};

}  // namespace vrd
