#pragma once
// How clean a force signal is over one press of a finger: what a user feels as steps, wobble and
// delay (issue: "what the fingers feel"). Pure functions of per-step samples.

#include <cstddef>
#include <limits>
#include <span>

namespace vrd {

struct SignalQuality {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  /// Total variation / (2 x peak): 1 for one clean rise and fall, more for every wobble.
  double roughness = kNaN;
  /// Spearman rank correlation of force with depth while loading: 1 when the force only ever
  /// rises with the depth.
  double loadingSpearman = kNaN;
  /// Standard deviation / mean of the force while the depth holds still.
  double holdNoise = kNaN;
  /// Steps by which the force trails the depth: the lag (0 to 30) of their largest
  /// cross-correlation while the depth is > 0.
  int lagSteps = 0;
  double peak = 0.0;  ///< the largest force
};

/// One press sampled once per step: `depth` (indentation, > 0 in contact) and `force` over the
/// whole press, the depth still in [holdBegin, holdEnd). Loading is every step before holdBegin
/// with depth > 0. NaN where a figure has too few samples (or a zero peak or mean).
SignalQuality signalQuality(std::span<const double> depth, std::span<const double> force, std::size_t holdBegin,
                            std::size_t holdEnd);

/// Spearman's rank correlation of x and y (ties get their mean rank); NaN for fewer than 3 pairs
/// or a constant series.
double spearman(std::span<const double> x, std::span<const double> y);

}  // namespace vrd
