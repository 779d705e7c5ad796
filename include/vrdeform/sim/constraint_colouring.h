#pragma once
// Graph colouring of a constraint array: constraints of one colour share no particle, so within a
// colour they commute and may be projected at once, in SIMD lanes and across threads, giving
// exactly the result of projecting them one after another (Gauss-Seidel over the colours in turn).

#include <array>
#include <cstdint>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

/// A solve order: colour k holds order[start[k], start[k + 1]). The constraints from start.back()
/// on (a few that fit no colour, or were in colours too small to be worth a pass) follow one at a
/// time in the remainder.
struct Colouring {
  std::vector<Index> order;                ///< a permutation of the constraints
  std::vector<std::uint32_t> colourStart;  ///< colours + 1 entries; empty: all in the remainder
};

/// Greedy colouring that balances the colours: each constraint, in input order, joins the
/// smallest colour none of its particles is in yet, and opens a new colour (up to 64) only when
/// there is none. Then, where they fit, constraints move out of colours whose size is not a
/// multiple of `batch` (the widest SIMD lanes) into other such colours, so that fewer batches run
/// with idle lanes. Within a colour the input order is kept (neighbouring constraints stay near
/// each other in memory). Colours with fewer than `minColourSize` constraints go to the remainder.
template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize,
                            std::size_t batch = 16);

/// True when colourStart is non-decreasing within [0, constraints.size()] and no two constraints of
/// one colour [colourStart[k], colourStart[k + 1]) share a particle.
template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart);

}  // namespace vrd
