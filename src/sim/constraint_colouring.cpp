#include "vrdeform/sim/constraint_colouring.h"

#include <algorithm>
#include <limits>

namespace vrd {
namespace {

constexpr int kMaxColours = 64;  // one bit per colour in a particle's mask

// Moves constraints out of colours whose last batch of `batch` lanes is partly empty into other
// such colours where they fit, smallest partial batch first, so that fewer batches run with idle
// lanes (a partial batch costs about as much as a full one). A colour whose whole partial batch
// finds room elsewhere ends on a full batch, or empty.
template <std::size_t N>
void fillBatches(const std::vector<std::array<Index, N>>& constraints, std::size_t batch, std::vector<int>& colourOf,
                 std::vector<std::size_t>& size, std::vector<std::uint64_t>& used) {
  const int colours = int(size.size());
  std::vector<std::vector<Index>> members(size.size());
  for (std::size_t k = 0; k < constraints.size(); ++k)
    if (colourOf[k] >= 0) members[colourOf[k]].push_back(Index(k));
  const auto tail = [&](int c) { return size[c] % batch; };
  std::vector<int> byTail(colours);
  for (int c = 0; c < colours; ++c) byTail[c] = c;
  std::stable_sort(byTail.begin(), byTail.end(), [&](int a, int b) { return tail(a) < tail(b); });
  for (int from : byTail) {
    if (tail(from) == 0) continue;
    // Where each of `from`'s constraints could go: the fullest partial batch it fits in.
    std::vector<std::pair<Index, int>> moves;
    std::vector<std::size_t> room(size.size());
    for (int c = 0; c < colours; ++c) room[c] = c == from || tail(c) == 0 ? 0 : batch - tail(c);
    for (Index k : members[from]) {
      if (moves.size() == tail(from)) break;
      std::uint64_t taken = 0;
      for (Index p : constraints[k]) taken |= used[p];
      int best = -1;
      for (int c = 0; c < colours; ++c)
        if (room[c] > 0 && !(taken >> c & 1u) && (best < 0 || room[c] < room[best])) best = c;
      if (best < 0) continue;
      --room[best];
      moves.push_back({k, best});
      for (Index p : constraints[k]) used[p] |= std::uint64_t(1) << best;  // its later moves see it there
    }
    if (moves.size() < tail(from)) {  // not all of it: undo the reservations
      for (const auto& [k, to] : moves)
        for (Index p : constraints[k]) used[p] &= ~(std::uint64_t(1) << to);
      continue;
    }
    for (const auto& [k, to] : moves) {
      for (Index p : constraints[k]) used[p] &= ~(std::uint64_t(1) << from);
      colourOf[k] = to;
      --size[from];
      ++size[to];
      members[to].push_back(k);
      std::erase(members[from], k);
    }
  }
}

template <std::size_t N>
Colouring colourAll(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize,
                    std::size_t batch) {
  constexpr int kNone = -1;
  Index particles = 0;
  for (const auto& c : constraints)
    for (Index p : c) particles = std::max(particles, p + 1);
  std::vector<std::uint64_t> used(particles, 0);  // colours each particle is in
  std::vector<int> colourOf(constraints.size(), kNone);
  std::vector<std::size_t> size;
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    std::uint64_t taken = 0;
    for (Index p : constraints[k]) taken |= used[p];
    int best = kNone;
    for (int c = 0; c < int(size.size()); ++c)
      if (!(taken >> c & 1u) && (best == kNone || size[c] < size[best])) best = c;
    if (best == kNone && size.size() < kMaxColours) {
      best = int(size.size());
      size.push_back(0);
    }
    if (best == kNone) continue;  // to the remainder
    colourOf[k] = best;
    ++size[best];
    for (Index p : constraints[k]) used[p] |= std::uint64_t(1) << best;
  }
  if (batch > 1) fillBatches(constraints, batch, colourOf, size, used);

  // Big colours first (largest first), the small ones and the uncoloured in the remainder.
  std::vector<int> colours;
  for (int c = 0; c < int(size.size()); ++c)
    if (size[c] >= std::max<std::size_t>(minColourSize, 1)) colours.push_back(c);
  std::stable_sort(colours.begin(), colours.end(), [&](int a, int b) { return size[a] > size[b]; });
  std::vector<int> rank(size.size(), kNone);
  for (int r = 0; r < int(colours.size()); ++r) rank[colours[r]] = r;

  Colouring out;
  out.order.reserve(constraints.size());
  for (int r = 0; r < int(colours.size()); ++r) {
    out.colourStart.push_back(std::uint32_t(out.order.size()));
    for (std::size_t k = 0; k < constraints.size(); ++k)
      if (colourOf[k] == colours[r]) out.order.push_back(Index(k));
  }
  if (!colours.empty()) out.colourStart.push_back(std::uint32_t(out.order.size()));
  for (std::size_t k = 0; k < constraints.size(); ++k)
    if (colourOf[k] == kNone || rank[colourOf[k]] == kNone) out.order.push_back(Index(k));
  return out;
}

}  // namespace

template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize,
                            std::size_t batch, const std::vector<std::uint8_t>& partOf) {
  if (partOf.empty()) return colourAll(constraints, minColourSize, batch);
  // Group g < parts: the constraints wholly in part g; group `parts`: the seam.
  const std::size_t parts = std::size_t(*std::max_element(partOf.begin(), partOf.end())) + 1;
  std::vector<std::vector<Index>> members(parts + 1);
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    std::size_t group = partOf.at(constraints[k][0]);
    for (Index p : constraints[k])
      if (partOf.at(p) != group) group = parts;
    members[group].push_back(Index(k));
  }
  Colouring out;
  std::vector<Index> remainder;
  for (const std::vector<Index>& group : members) {
    out.partColours.push_back(std::uint32_t(out.colourStart.size()));
    std::vector<std::array<Index, N>> own;
    for (Index k : group) own.push_back(constraints[k]);
    const Colouring c = colourAll(own, minColourSize, batch);
    const std::size_t base = out.order.size(), coloured = c.colourStart.empty() ? 0 : c.colourStart.back();
    for (std::size_t k = 0; k + 1 < c.colourStart.size(); ++k)
      out.colourStart.push_back(std::uint32_t(base + c.colourStart[k]));
    for (std::size_t i = 0; i < coloured; ++i) out.order.push_back(group[c.order[i]]);
    for (std::size_t i = coloured; i < c.order.size(); ++i) remainder.push_back(group[c.order[i]]);
  }
  if (out.colourStart.empty())
    out.partColours.clear();  // no colour at all
  else
    out.colourStart.push_back(std::uint32_t(out.order.size()));
  out.order.insert(out.order.end(), remainder.begin(), remainder.end());
  return out;
}

std::vector<std::uint8_t> slabsOf(const std::vector<Vec3>& points, int parts) {
  const auto cut = [&](int axis) {
    std::vector<Index> byHeight(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) byHeight[i] = Index(i);
    std::stable_sort(byHeight.begin(), byHeight.end(),
                     [&](Index a, Index b) { return points[a][axis] < points[b][axis]; });
    std::vector<std::uint8_t> slab(points.size());
    for (std::size_t r = 0; r < byHeight.size(); ++r)
      slab[byHeight[r]] = std::uint8_t(r * std::size_t(parts) / points.size());
    return slab;
  };
  // Neighbours in memory in different slabs share cache lines that both threads write: cut across
  // the axis along which the points' order changes slab least often (a grid's slowest axis).
  const auto changes = [](const std::vector<std::uint8_t>& slab) {
    std::size_t n = 0;
    for (std::size_t i = 1; i < slab.size(); ++i) n += slab[i] != slab[i - 1];
    return n;
  };
  std::vector<std::uint8_t> best = cut(0);
  for (int axis = 1; axis < 3; ++axis)
    if (std::vector<std::uint8_t> slab = cut(axis); changes(slab) < changes(best)) best = std::move(slab);
  return best;
}

template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart, const std::vector<std::uint32_t>& partColours) {
  if (colourStart.empty()) return partColours.empty();
  if (colourStart.back() > constraints.size()) return false;
  Index particles = 0;
  for (const auto& c : constraints)
    for (Index p : c) particles = std::max(particles, p + 1);
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> seenIn(particles, kNone);
  for (std::size_t k = 0; k + 1 < colourStart.size(); ++k) {
    if (colourStart[k] > colourStart[k + 1]) return false;
    for (std::uint32_t c = colourStart[k]; c < colourStart[k + 1]; ++c) {
      for (Index p : constraints[c])
        if (seenIn[p] == k) return false;
      for (Index p : constraints[c]) seenIn[p] = std::uint32_t(k);
    }
  }
  if (partColours.empty()) return true;
  // Parts: non-decreasing colour ranges, the seam's last; no particle in two parts.
  const std::size_t colours = colourStart.size() - 1;
  if (partColours.front() != 0 || partColours.back() > colours) return false;
  std::vector<std::uint32_t> partOf(particles, kNone);
  for (std::size_t part = 0; part + 1 < partColours.size(); ++part) {
    if (partColours[part] > partColours[part + 1]) return false;
    for (std::uint32_t c = colourStart[partColours[part]]; c < colourStart[partColours[part + 1]]; ++c)
      for (Index p : constraints[c]) {
        if (partOf[p] != kNone && partOf[p] != part) return false;
        partOf[p] = std::uint32_t(part);
      }
  }
  return true;
}

template Colouring colourConstraints<2>(const std::vector<std::array<Index, 2>>&, std::size_t, std::size_t,
                                        const std::vector<std::uint8_t>&);
template Colouring colourConstraints<4>(const std::vector<std::array<Index, 4>>&, std::size_t, std::size_t,
                                        const std::vector<std::uint8_t>&);
template bool coloursIndependent<2>(const std::vector<std::array<Index, 2>>&, const std::vector<std::uint32_t>&,
                                    const std::vector<std::uint32_t>&);
template bool coloursIndependent<4>(const std::vector<std::array<Index, 4>>&, const std::vector<std::uint32_t>&,
                                    const std::vector<std::uint32_t>&);

}  // namespace vrd
