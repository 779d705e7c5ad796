#pragma once
// Counterbalancing for a within-subject study: the order in which participant k meets the
// conditions, from a balanced Latin square (Williams' design), so that across a complete set of
// participants every condition comes at every position equally often and follows every other
// condition equally often (first-order carry-over balanced).

#include <cstddef>
#include <vector>

namespace vrd {

/// Participants in one complete square: n for an even number of conditions, 2n for an odd one
/// (the square and its mirror).
std::size_t latinSquareRows(std::size_t conditions);

/// Participant `participant`'s order of the conditions 0..conditions-1 (participant k and
/// k + latinSquareRows(conditions) share it). Throws vrd::Error for no conditions.
std::vector<std::size_t> latinSquareOrder(std::size_t conditions, std::size_t participant);

}  // namespace vrd
