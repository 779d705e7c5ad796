#include "vrdeform/metrics/signal_quality.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace vrd {
namespace {

// Ranks 0..n-1 of v, ties sharing their mean rank.
std::vector<double> ranks(std::span<const double> v) {
  std::vector<std::size_t> order(v.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && v[order[j + 1]] == v[order[i]]) ++j;
    for (std::size_t k = i; k <= j; ++k) r[order[k]] = 0.5 * double(i + j);
    i = j + 1;
  }
  return r;
}

double pearson(std::span<const double> x, std::span<const double> y) {
  const double n = double(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n, my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : SignalQuality::kNaN;
}

}  // namespace

double spearman(std::span<const double> x, std::span<const double> y) {
  if (x.size() != y.size() || x.size() < 3) return SignalQuality::kNaN;
  const std::vector<double> rx = ranks(x), ry = ranks(y);
  return pearson(rx, ry);
}

SignalQuality signalQuality(std::span<const double> depth, std::span<const double> force, std::size_t holdBegin,
                            std::size_t holdEnd) {
  SignalQuality q;
  const std::size_t n = std::min(depth.size(), force.size());
  holdEnd = std::min(holdEnd, n);
  holdBegin = std::min(holdBegin, holdEnd);
  if (n == 0) return q;
  double variation = 0;
  for (std::size_t i = 0; i < n; ++i) {
    q.peak = std::max(q.peak, force[i]);
    if (i > 0) variation += std::abs(force[i] - force[i - 1]);
  }
  if (q.peak > 0) q.roughness = variation / (2 * q.peak);

  std::vector<double> loadDepth, loadForce;
  for (std::size_t i = 0; i < holdBegin; ++i)
    if (depth[i] > 0) loadDepth.push_back(depth[i]), loadForce.push_back(force[i]);
  q.loadingSpearman = spearman(loadDepth, loadForce);

  if (holdEnd - holdBegin >= 2) {
    const auto hold = force.subspan(holdBegin, holdEnd - holdBegin);
    const double mean = std::accumulate(hold.begin(), hold.end(), 0.0) / double(hold.size());
    double var = 0;
    for (double f : hold) var += (f - mean) * (f - mean);
    if (mean > 0) q.holdNoise = std::sqrt(var / double(hold.size())) / mean;
  }

  // Lag: the shift of the force that best matches the depth while the finger is in (so that the
  // descent through the air, with no force, does not count).
  std::size_t first = 0, last = n;
  while (first < n && !(depth[first] > 0)) ++first;
  while (last > first && !(depth[last - 1] > 0)) --last;
  double best = -2;
  for (std::size_t lag = 0; lag <= 30 && first + lag + 3 <= last; ++lag) {
    const std::size_t length = last - first - lag;
    const double c = pearson(depth.subspan(first, length), force.subspan(first + lag, length));
    if (c > best) best = c, q.lagSteps = int(lag);
  }
  return q;
}

}  // namespace vrd
