#include "vrdeform/metrics/wilcoxon.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "vrdeform/error.h"

namespace vrd {
namespace {

// P(W+ <= w) and P(W+ >= w) under the null hypothesis: each of ranks 1..n positive with
// probability 1/2, so the counts of sign patterns with each sum come from the subset-sum
// recurrence (in doubles: 2^50 patterns are exact in them up to the last bits).
std::pair<double, double> exactTails(std::size_t n, double w) {
  const std::size_t most = n * (n + 1) / 2;
  std::vector<double> count(most + 1, 0.0);
  count[0] = 1.0;
  for (std::size_t rank = 1; rank <= n; ++rank)
    for (std::size_t s = most; s >= rank; --s) count[s] += count[s - rank];
  const double total = std::ldexp(1.0, int(n));
  const auto at = std::size_t(std::llround(w));
  double below = 0.0, above = 0.0;
  for (std::size_t s = 0; s <= most; ++s) (s <= at ? below : above) += count[s];
  above += count[at];  // P(W+ >= w) includes w itself
  return {below / total, above / total};
}

double normalUpperTail(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

}  // namespace

WilcoxonResult wilcoxonSignedRank(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size())
    throw Error(fmt::format("wilcoxon: {} values against {}: the samples must be paired", a.size(), b.size()));
  std::vector<double> d;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(a[i]) || !std::isfinite(b[i]))
      throw Error(fmt::format("wilcoxon: pair {} is not finite ({}, {})", i + 1, a[i], b[i]));
    if (a[i] != b[i]) d.push_back(a[i] - b[i]);
  }
  WilcoxonResult r;
  r.n = d.size();
  if (r.n == 0) return r;

  // Ranks of |d|, ties sharing their mean rank; and the tie groups' t^3 - t for the variance.
  std::vector<std::size_t> order(r.n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return std::abs(d[i]) < std::abs(d[j]); });
  double ties = 0.0;
  for (std::size_t first = 0; first < r.n;) {
    std::size_t last = first;
    while (last + 1 < r.n && std::abs(d[order[last + 1]]) == std::abs(d[order[first]])) ++last;
    const double rank = 0.5 * double(first + last) + 1.0;  // ranks count from 1
    for (std::size_t k = first; k <= last; ++k) (d[order[k]] > 0 ? r.wPlus : r.wMinus) += rank;
    const double t = double(last - first + 1);
    ties += t * t * t - t;
    first = last + 1;
  }

  const double n = double(r.n);
  const double mean = n * (n + 1) / 4, sd = std::sqrt(n * (n + 1) * (2 * n + 1) / 24 - ties / 48);
  r.z = sd > 0 ? (r.wPlus - mean) / sd : 0.0;
  r.effectSize = std::abs(r.z) / std::sqrt(n);
  r.exact = r.n <= kExactPairs && ties == 0.0;
  if (r.exact) {
    const auto [below, above] = exactTails(r.n, r.wPlus);
    r.p = std::min(1.0, 2.0 * std::min(below, above));
  } else {
    r.p = std::min(1.0, 2.0 * normalUpperTail(std::abs(r.z)));
  }
  return r;
}

}  // namespace vrd
