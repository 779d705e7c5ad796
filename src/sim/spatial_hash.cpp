#include "vrdeform/sim/spatial_hash.h"

#include <algorithm>
#include <bit>

namespace vrd {

bool SpatialHash::cellsOf(const Box3f& box, Cells& out) const {
  constexpr double kRange = 1e12;  // cell coordinates well inside int64 and exact in double
  for (int d = 0; d < 3; ++d) {
    const double lo = std::floor(double(box.min()[d]) * invCell_), hi = std::floor(double(box.max()[d]) * invCell_);
    if (!(lo >= -kRange && hi <= kRange && lo <= hi)) return false;
    out.lo[d] = std::int64_t(lo);
    out.hi[d] = std::int64_t(hi);
  }
  return true;
}

void SpatialHash::build(std::span<const Box3f> boxes, float cellSize) {
  invCell_ = 1.0f / cellSize;
  oversized_.clear();
  // Each box's cells; the table gets about two slots per (cell, item) entry, so that few cells share one.
  std::vector<Cells>& cells = cells_;
  cells.resize(boxes.size());
  const auto cellCount = [](const Cells& c) {
    return (c.hi[0] - c.lo[0] + 1) * (c.hi[1] - c.lo[1] + 1) * (c.hi[2] - c.lo[2] + 1);
  };
  std::size_t entries = 0;
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    if (!cellsOf(boxes[k], cells[k]) || cellCount(cells[k]) > kMostCells) {
      oversized_.push_back(Index(k));
      cells[k] = Cells{{0, 0, 0}, {-1, -1, -1}};  // no cells
    } else {
      entries += std::size_t(cellCount(cells[k]));
    }
  }
  const std::size_t slots = std::bit_ceil(std::max<std::size_t>(2 * entries, 64));
  mask_ = slots - 1;
  start_.assign(slots + 1, 0);
  const auto each = [&](const Cells& c, auto&& f) {
    for (std::int64_t x = c.lo[0]; x <= c.hi[0]; ++x)
      for (std::int64_t y = c.lo[1]; y <= c.hi[1]; ++y)
        for (std::int64_t z = c.lo[2]; z <= c.hi[2]; ++z) f(slot(x, y, z));
  };
  // Counting sort by slot: count, prefix sums, then fill.
  for (const Cells& c : cells) each(c, [&](std::size_t s) { ++start_[s + 1]; });
  for (std::size_t s = 0; s < slots; ++s) start_[s + 1] += start_[s];
  items_.resize(start_[slots]);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t k = 0; k < boxes.size(); ++k) each(cells[k], [&](std::size_t s) { items_[fill_[s]++] = Index(k); });
}

}  // namespace vrd
