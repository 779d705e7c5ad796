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
/// colourStart.back() on (a few that fit no colour, or were in colours too small to be worth a
/// pass) follow one at a time in the remainder.
struct Colouring {
  std::vector<Index> order;                ///< a permutation of the constraints
  std::vector<std::uint32_t> colourStart;  ///< colours + 1 entries; empty: all in the remainder
  /// With parts (partOf below), one entry per part and one for the seam: colours
  /// [partColours[p], partColours[p + 1]) hold the constraints whose particles all lie in part p,
  /// and the colours from partColours.back() on the seam's (constraints across parts). Parts share
  /// no particle, so each may be swept whole by its own thread while the others sweep theirs.
  std::vector<std::uint32_t> partColours;
};

/// Greedy colouring that balances the colours: each constraint, in input order, joins the
/// smallest colour none of its particles is in yet, and opens a new colour (up to 64) only when
/// there is none. Then, where they fit, constraints move out of colours whose size is not a
/// multiple of `batch` (the widest SIMD lanes) into other such colours, so that fewer batches run
/// with idle lanes. Within a colour the input order is kept (neighbouring constraints stay near
/// each other in memory). Colours with fewer than `minColourSize` constraints go to the remainder.
/// With `partOf` (each particle's part, from 0): each part's constraints are coloured on their own,
/// part after part, then the seam's.
template <std::size_t N>
Colouring colourConstraints(const std::vector<std::array<Index, N>>& constraints, std::size_t minColourSize,
                            std::size_t batch = 16, const std::vector<std::uint8_t>& partOf = {});

/// Cuts points into `parts` slabs of (nearly) equal count across x, y or z, whichever puts the
/// fewest neighbours in the points' order into different slabs (threads sweeping different slabs
/// then seldom write the same cache line): each point's slab, from 0.
std::vector<std::uint8_t> slabsOf(const std::vector<Vec3>& points, int parts);

/// True when colourStart is non-decreasing within [0, constraints.size()], no two constraints of
/// one colour [colourStart[k], colourStart[k + 1]) share a particle and, with partColours, no two
/// constraints of different parts do.
template <std::size_t N>
bool coloursIndependent(const std::vector<std::array<Index, N>>& constraints,
                        const std::vector<std::uint32_t>& colourStart,
                        const std::vector<std::uint32_t>& partColours = {});

}  // namespace vrd
