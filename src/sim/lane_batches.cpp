#include "vrdeform/sim/lane_batches.h"

#include <algorithm>

namespace vrd {
namespace {

constexpr std::size_t kWindow = 64;  // candidates looked at to fill one group

template <std::size_t N>
bool sharesParticle(const std::array<Index, N>& c, const std::array<Index, N>* group, std::size_t size) {
  for (std::size_t g = 0; g < size; ++g)
    for (Index a : c)
      if (std::find(group[g].begin(), group[g].end(), a) != group[g].end()) return true;
  return false;
}

}  // namespace

template <std::size_t N>
LaneOrder orderForLanes(const std::vector<std::array<Index, N>>& constraints) {
  const std::size_t n = constraints.size();
  LaneOrder out;
  out.order.reserve(n);
  std::vector<char> taken(n, 0);
  std::size_t head = 0;
  for (;;) {
    while (head < n && taken[head]) ++head;
    std::array<Index, kLanes> picked;
    std::array<std::array<Index, N>, kLanes> group;
    std::size_t size = 0, scanned = 0;
    for (std::size_t k = head; k < n && size < kLanes && scanned < kWindow; ++k) {
      if (taken[k]) continue;
      ++scanned;
      if (sharesParticle(constraints[k], group.data(), size)) continue;
      group[size] = constraints[k];
      picked[size++] = Index(k);
    }
    if (size < kLanes) break;
    for (Index k : picked) {
      taken[k] = 1;
      out.order.push_back(k);
    }
  }
  out.batched = out.order.size();
  for (std::size_t k = 0; k < n; ++k)
    if (!taken[k]) out.order.push_back(Index(k));
  return out;
}

template <std::size_t N>
bool lanesIndependent(const std::vector<std::array<Index, N>>& constraints, std::size_t batched) {
  if (batched % kLanes != 0 || batched > constraints.size()) return false;
  for (std::size_t b = 0; b < batched; b += kLanes)
    for (std::size_t k = 1; k < kLanes; ++k)
      if (sharesParticle(constraints[b + k], &constraints[b], k)) return false;
  return true;
}

template LaneOrder orderForLanes<2>(const std::vector<std::array<Index, 2>>&);
template LaneOrder orderForLanes<4>(const std::vector<std::array<Index, 4>>&);
template bool lanesIndependent<2>(const std::vector<std::array<Index, 2>>&, std::size_t);
template bool lanesIndependent<4>(const std::vector<std::array<Index, 4>>&, std::size_t);

}  // namespace vrd
