#pragma once
// The threads that solve one substep together (SolverSettings::threads): an OpenMP team, each
// member running the same sweep and taking its share of the work (sweepColours in world.cpp: a
// group of a big body's constraints, or a share of every colour), with barriers between the parts
// that may touch the same particles. What runs at once shares no particle, so the result is bit for
// bit the one-thread result.

#include <omp.h>

#include <cstddef>
#include <utility>

namespace vrd {

struct SolverTeam {
  int index = 0;  ///< this thread's place in the team
  int size = 1;   ///< threads in the team

  /// The team of the enclosing OpenMP parallel region (or a team of one outside any).
  static SolverTeam current() { return {omp_get_thread_num(), omp_get_num_threads()}; }

  bool leader() const { return index == 0; }
  bool last() const { return index + 1 == size; }
  /// Waits until every member has reached it; nothing in a team of one.
  void barrier() const {
    if (size > 1) {
#pragma omp barrier
    }
  }
  /// This member's share of [begin, end), cut at multiples of `align` from begin so that SIMD
  /// batches stay whole.
  std::pair<std::size_t, std::size_t> share(std::size_t begin, std::size_t end, std::size_t align) const {
    const std::size_t blocks = (end - begin + align - 1) / align;
    const auto cut = [&](int k) { return std::min(end, begin + blocks * std::size_t(k) / std::size_t(size) * align); };
    return {cut(index), cut(index + 1)};
  }
};

}  // namespace vrd
