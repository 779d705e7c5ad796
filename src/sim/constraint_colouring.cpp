#include "vrdeform/sim/constraint_colouring.h"

#include <algorithm>
#include <limits>

namespace vrd {
namespace {

constexpr int kMaxColours = 64;  // one bit per colour in a particle's mask

}  // namespace

template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize) {
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

template Colouring colourConstraints<2>(const std::vector<std::array<Index, 2>>&, std::size_t);
template Colouring colourConstraints<4>(const std::vector<std::array<Index, 4>>&, std::size_t);
template bool coloursIndependent<2>(const std::vector<std::array<Index, 2>>&, const std::vector<std::uint32_t>&);
template bool coloursIndependent<4>(const std::vector<std::array<Index, 4>>&, const std::vector<std::uint32_t>&);

}  // namespace vrd
