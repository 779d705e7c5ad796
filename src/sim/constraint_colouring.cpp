#include "vrdeform/sim/constraint_colouring.h"

#include <algorithm>
#include <limits>
#include <optional>

namespace vrd {
namespace {

constexpr int kMaxColours = 64;  // one bit per colour in a particle's mask

// One past the highest particle index the constraints use.
template <std::size_t N>
Index particleCount(const std::vector<std::array<Index, N>>& constraints) {
  Index particles = 0;
  for (const auto& c : constraints)
    for (Index p : c) particles = std::max(particles, p + 1);
  return particles;
}

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
Colouring colourAll(const std::vector<std::array<Index, N>>& constraints, std::size_t batch) {
  constexpr int kNone = -1;
  const Index particles = particleCount(constraints);
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

  // Largest first (fillBatches may have emptied some), the uncoloured in the remainder.
  std::vector<int> colours;
  for (int c = 0; c < int(size.size()); ++c)
    if (size[c] > 0) colours.push_back(c);
  std::stable_sort(colours.begin(), colours.end(), [&](int a, int b) { return size[a] > size[b]; });

  Colouring out;
  out.order.reserve(constraints.size());
  for (int r = 0; r < int(colours.size()); ++r) {
    out.colourStart.push_back(std::uint32_t(out.order.size()));
    for (std::size_t k = 0; k < constraints.size(); ++k)
      if (colourOf[k] == colours[r]) out.order.push_back(Index(k));
  }
  if (!colours.empty()) out.colourStart.push_back(std::uint32_t(out.order.size()));
  for (std::size_t k = 0; k < constraints.size(); ++k)
    if (colourOf[k] == kNone) out.order.push_back(Index(k));
  return out;
}

}  // namespace

template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t batch,
                            const std::vector<std::uint8_t>& groupOf) {
  if (groupOf.empty()) return colourAll(constraints, batch);
  std::vector<std::vector<Index>> members(std::size_t(*std::max_element(groupOf.begin(), groupOf.end())) + 1);
  for (std::size_t k = 0; k < constraints.size(); ++k) members[groupOf.at(k)].push_back(Index(k));
  Colouring out;
  std::vector<Index> remainder;
  for (const std::vector<Index>& group : members) {
    out.groupColours.push_back(std::uint32_t(out.colourStart.size()));
    std::vector<std::array<Index, N>> own;
    for (Index k : group) own.push_back(constraints[k]);
    const Colouring c = colourAll(own, batch);
    const std::size_t base = out.order.size(), coloured = c.colourStart.empty() ? 0 : c.colourStart.back();
    for (std::size_t k = 0; k + 1 < c.colourStart.size(); ++k)
      out.colourStart.push_back(std::uint32_t(base + c.colourStart[k]));
    for (std::size_t i = 0; i < coloured; ++i) out.order.push_back(group[c.order[i]]);
    for (std::size_t i = coloured; i < c.order.size(); ++i) remainder.push_back(group[c.order[i]]);
  }
  out.groupColours.push_back(std::uint32_t(out.colourStart.size()));
  if (out.colourStart.empty())
    out.groupColours.clear();  // no colour at all
  else
    out.colourStart.push_back(std::uint32_t(out.order.size()));
  out.order.insert(out.order.end(), remainder.begin(), remainder.end());
  return out;
}

Slabs slabsOf(const std::vector<Vec3>& points, int parts, int skipAxis) {
  const auto cut = [&](int axis) {
    std::vector<Index> byHeight(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) byHeight[i] = Index(i);
    std::stable_sort(byHeight.begin(), byHeight.end(),
                     [&](Index a, Index b) { return points[a][axis] < points[b][axis]; });
    Slabs slabs{std::vector<std::uint8_t>(points.size()), axis};
    for (std::size_t r = 0; r < byHeight.size(); ++r)
      slabs.of[byHeight[r]] = std::uint8_t(r * std::size_t(parts) / points.size());
    return slabs;
  };
  const auto changes = [](const Slabs& s) {
    std::size_t n = 0;
    for (std::size_t i = 1; i < s.of.size(); ++i) n += s.of[i] != s.of[i - 1];
    return n;
  };
  std::optional<Slabs> best;
  for (int axis = 0; axis < 3; ++axis)
    if (axis != skipAxis)
      if (Slabs s = cut(axis); !best || changes(s) < changes(*best)) best = std::move(s);
  return *best;
}

template <std::size_t N>
Colouring levelOrder(const std::vector<std::array<Index, N>>& constraints) {
  std::vector<std::uint32_t> levelOf(constraints.size());
  std::vector<std::uint32_t> next(particleCount(constraints), 0);  // next[p]: the first level free of p
  std::uint32_t levels = 0;
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    std::uint32_t level = 0;
    for (Index p : constraints[k]) level = std::max(level, next[p]);
    for (Index p : constraints[k]) next[p] = level + 1;
    levelOf[k] = level;
    levels = std::max(levels, level + 1);
  }
  Colouring out;
  out.colourStart.assign(levels + 1, 0);
  for (std::uint32_t level : levelOf) ++out.colourStart[level + 1];
  for (std::uint32_t l = 0; l < levels; ++l) out.colourStart[l + 1] += out.colourStart[l];
  out.order.resize(constraints.size());
  std::vector<std::uint32_t> fill(out.colourStart.begin(), out.colourStart.end() - 1);
  for (std::size_t k = 0; k < constraints.size(); ++k) out.order[fill[levelOf[k]]++] = Index(k);
  return out;
}

template <std::size_t N>
std::vector<std::uint8_t> twoThreadGroups(const std::vector<std::array<Index, N>>& constraints,
                                          const std::vector<Vec3>& rest) {
  const auto within = [](const std::array<Index, N>& c, const std::vector<std::uint8_t>& slab) {
    return std::all_of(c.begin(), c.end(), [&](Index p) { return slab[p] == slab[c[0]]; });
  };
  const Slabs first = slabsOf(rest, 2);
  std::vector<std::uint8_t> group(constraints.size(), 4);
  std::vector<char> inSeam(rest.size(), 0);
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    if (within(constraints[k], first.of))
      group[k] = first.of[constraints[k][0]];
    else
      for (Index p : constraints[k]) inSeam[p] = 1;
  }
  // The seam's particles (in index order, as slabsOf wants them), halved across another axis.
  std::vector<Index> seam;
  std::vector<Vec3> seamRest;
  for (Index p = 0; p < rest.size(); ++p)
    if (inSeam[p]) seam.push_back(p), seamRest.push_back(rest[p]);
  if (seam.empty()) return group;
  const Slabs second = slabsOf(seamRest, 2, first.axis);
  std::vector<std::uint8_t> half(rest.size(), 0);
  for (std::size_t i = 0; i < seam.size(); ++i) half[seam[i]] = second.of[i];
  for (std::size_t k = 0; k < constraints.size(); ++k)
    if (group[k] == 4 && within(constraints[k], half)) group[k] = std::uint8_t(2 + half[constraints[k][0]]);
  return group;
}

template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart, const std::vector<std::uint32_t>& groupColours) {
  if (colourStart.empty()) return groupColours.empty();
  if (colourStart.back() > constraints.size()) return false;
  const Index particles = particleCount(constraints);
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
  if (groupColours.empty()) return true;
  const std::size_t colours = colourStart.size() - 1;
  if (groupColours.front() != 0 || groupColours.back() != colours) return false;
  for (std::size_t g = 0; g + 1 < groupColours.size(); ++g)
    if (groupColours[g] > groupColours[g + 1]) return false;
  // Groups 2L and 2L + 1: the particles of the first, then none of them in the second.
  std::vector<std::uint32_t> pairOf(particles, kNone);
  for (std::size_t g = 0; g + 2 < groupColours.size(); g += 2) {
    const auto range = [&](std::size_t group) {
      return std::pair{colourStart[groupColours[group]], colourStart[groupColours[group + 1]]};
    };
    for (auto [begin, end] = range(g); begin < end; ++begin)
      for (Index p : constraints[begin]) pairOf[p] = std::uint32_t(g);
    for (auto [begin, end] = range(g + 1); begin < end; ++begin)
      for (Index p : constraints[begin])
        if (pairOf[p] == g) return false;
  }
  return true;
}

#define VRD_COLOURING(N)                                                                                           \
  template Colouring colourConstraints<N>(const std::vector<std::array<Index, N>>&, std::size_t,                   \
                                          const std::vector<std::uint8_t>&);                                       \
  template Colouring levelOrder<N>(const std::vector<std::array<Index, N>>&);                                      \
  template std::vector<std::uint8_t> twoThreadGroups<N>(const std::vector<std::array<Index, N>>&,                  \
                                                        const std::vector<Vec3>&);                                 \
  template bool coloursIndependent<N>(const std::vector<std::array<Index, N>>&, const std::vector<std::uint32_t>&, \
                                      const std::vector<std::uint32_t>&);
VRD_COLOURING(2)
VRD_COLOURING(4)
#undef VRD_COLOURING

}  // namespace vrd
