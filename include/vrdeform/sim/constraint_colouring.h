#pragma once
// Graph colouring of a constraint array: constraints of one colour share no particle, so within a
// colour they commute and may be projected at once, in SIMD lanes and across threads, giving
// exactly the result of projecting them one after another (Gauss-Seidel over the colours in turn).

#include <array>
#include <cstdint>
#include <vector>

#include "vrdeform/math/types.h"

namespace vrd {

/// A solve order: colour k holds order[colourStart[k], colourStart[k + 1]). The constraints from
/// colourStart.back() on (those that fit none of the 64 colours) follow one at a time in the
/// remainder.
struct Colouring {
  std::vector<Index> order;                ///< a permutation of the constraints
  std::vector<std::uint32_t> colourStart;  ///< colours + 1 entries; empty: all in the remainder
  /// With groups (groupOf below): colours [groupColours[g], groupColours[g + 1]) hold group g's
  /// constraints, groups + 1 entries. Empty: no groups.
  std::vector<std::uint32_t> groupColours;
};

/// Greedy colouring that balances the colours: each constraint, in input order, joins the
/// smallest colour none of its particles is in yet, and opens a new colour (up to 64) only when
/// there is none. Then, where they fit, constraints move out of colours whose size is not a
/// multiple of `batch` (the widest SIMD lanes) into other such colours, so that fewer batches run
/// with idle lanes. Within a colour the input order is kept (neighbouring constraints stay near
/// each other in memory). Colours are in order of size, largest first. With `groupOf` (each
/// constraint's group, from 0): each group is coloured on its own, group after group.
template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t batch = 16,
                            const std::vector<std::uint8_t>& groupOf = {});

/// Colours that keep the input order's result: each constraint goes one level after the last
/// earlier constraint that shares a particle with it (level 0 if none). Constraints of a level
/// share no particle, and any two that do keep their order, so sweeping the levels one after
/// another, each at once, gives exactly the one-at-a-time sweep in input order. For constraints
/// whose Gauss-Seidel order matters, such as bending (world.cpp). Within a level the input order
/// is kept; no remainder.
template <std::size_t N>
Colouring levelOrder(const std::vector<std::array<Index, N>>& constraints);

/// Points cut into `parts` slabs of (nearly) equal count across x, y or z (not `skipAxis`),
/// whichever puts the fewest neighbours in the points' order into different slabs: threads
/// sweeping different slabs then seldom write the same cache line.
struct Slabs {
  std::vector<std::uint8_t> of;  ///< each point's slab, from 0
  int axis = 0;
};
Slabs slabsOf(const std::vector<Vec3>& points, int parts, int skipAxis = -1);

/// Groups for two threads (Colouring::groupColours), by the particles' rest positions: 0 and 1,
/// the constraints wholly in one half of the body; 2 and 3, those across the cut but wholly in one
/// half of a second cut across the first (the seam, halved); 4, those across both cuts. Groups 0
/// and 1 share no particle, nor do 2 and 3, so two threads can sweep each pair at once.
template <std::size_t N>
std::vector<std::uint8_t> twoThreadGroups(const std::vector<std::array<Index, N>>& constraints,
                                          const std::vector<Vec3>& rest);

/// True when colourStart is non-decreasing within [0, constraints.size()], no two constraints of
/// one colour [colourStart[k], colourStart[k + 1]) share a particle and, with groupColours, the
/// groups cover the colours in order and groups 2L and 2L + 1 share no particle.
template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart,
                        const std::vector<std::uint32_t>& groupColours = {});

}  // namespace vrd
