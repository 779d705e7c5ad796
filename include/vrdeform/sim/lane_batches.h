#pragma once
// Ordering constraints so that each group of kLanes consecutive ones touches kLanes * N distinct
// particles. Constraints that share no particle commute, so the solver may project such a group
// at once in SIMD lanes and still compute exactly a serial Gauss-Seidel sweep in this order.

#include <array>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

inline constexpr std::size_t kLanes = 4;

struct LaneOrder {
  std::vector<Index> order;  ///< a permutation of the constraints
  std::size_t batched = 0;   ///< order[0, batched) forms groups of kLanes independent constraints
};

/// Greedy packing within a sliding window, so the order stays close to the input order (which
/// keeps neighbouring constraints near each other in memory and in the sweep). Constraints that
/// cannot be packed, at most a few at the end, follow in input order.
template <std::size_t N>
LaneOrder orderForLanes(const std::vector<std::array<Index, N>>& constraints);

/// True when each group of kLanes consecutive constraints in [0, batched) shares no particle.
template <std::size_t N>
bool lanesIndependent(const std::vector<std::array<Index, N>>& constraints, std::size_t batched);

}  // namespace vrd
