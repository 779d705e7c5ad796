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

}  // namespace

template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize,
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

template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart) {
  if (colourStart.empty()) return true;
  if (colourStart.back() > constraints.size()) return false;
  Index particles = 0;
  for (const auto& c : constraints)
    for (Index p : c) particles = std::max(particles, p + 1);
  std::vector<std::uint32_t> seenIn(particles, std::numeric_limits<std::uint32_t>::max());
  for (std::size_t k = 0; k + 1 < colourStart.size(); ++k) {
    if (colourStart[k] > colourStart[k + 1]) return false;
    for (std::uint32_t c = colourStart[k]; c < colourStart[k + 1]; ++c) {
      for (Index p : constraints[c])
        if (seenIn[p] == k) return false;
      for (Index p : constraints[c]) seenIn[p] = std::uint32_t(k);
    }
  }
  return true;
}

template Colouring colourConstraints<2>(const std::vector<std::array<Index, 2>>&, std::size_t, std::size_t);
template Colouring colourConstraints<4>(const std::vector<std::array<Index, 4>>&, std::size_t, std::size_t);
template bool coloursIndependent<2>(const std::vector<std::array<Index, 2>>&, const std::vector<std::uint32_t>&);
template bool coloursIndependent<4>(const std::vector<std::array<Index, 4>>&, const std::vector<std::uint32_t>&);

}  // namespace vrd
