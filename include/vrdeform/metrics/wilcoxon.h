#pragma once
// The Wilcoxon signed-rank test on paired samples: the paper's test of condition A against
// condition B on each questionnaire item (a within-subject study), the first piece of the study
// kit's statistics.

#include <cstddef>
#include <span>

namespace vrd {

struct WilcoxonResult {
  std::size_t n = 0;        ///< pairs with a non-zero difference (zero differences are dropped)
  double wPlus = 0.0;       ///< sum of the ranks of the positive differences a - b (ties: mean ranks)
  double wMinus = 0.0;      ///< the same for the negative ones; wPlus + wMinus = n (n + 1) / 2
  double p = 1.0;           ///< two-sided p-value
  bool exact = false;       ///< p from the exact distribution of W+ (else the normal approximation)
  double z = 0.0;           ///< (W+ - n (n + 1) / 4) / sd, the sd corrected for ties
  double effectSize = 0.0;  ///< r = |z| / sqrt(n)
};

/// Tests whether the differences a[i] - b[i] are symmetric about 0. Exact (the distribution of W+
/// over the 2^n sign patterns) when there are at most kExactPairs non-zero differences and no two
/// share a magnitude; otherwise the normal approximation with the tie correction of the variance,
/// without continuity correction (SciPy's `wilcoxon` defaults, `zero_method="wilcox"`). With no
/// non-zero difference, p is 1. Throws vrd::Error for spans of different sizes or a non-finite value.
WilcoxonResult wilcoxonSignedRank(std::span<const double> a, std::span<const double> b);

inline constexpr std::size_t kExactPairs = 50;

}  // namespace vrd
