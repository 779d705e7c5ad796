#include "vrdeform/io/tetrahedralise.h"

#include <fmt/format.h>

#include <cmath>

#include "vrdeform/error.h"
#include "vrdeform/mesh/isosurface_stuffing.h"
#include "vrdeform/mesh/surface_check.h"

namespace vrd {

const char* toString(Mesher mesher) { return mesher == Mesher::TetGen ? "tetgen" : "builtin"; }

namespace {

// Runs the mesher once per volume bound until the count is within tolerance of the target:
// count ~ volume / (c * bound) with c near 1 for the lattice and 1/4..1/2 for TetGen, so each
// run corrects the bound by the ratio it missed by, within the bracket of bounds known to give
// too many and too few tets (bisected when the ratio step leaves it: TetGen's count can jump).
template <typename Run>
Tetrahedralisation searchCount(Run&& run, double target, double initialBound, double aim) {
  Tetrahedralisation best;
  double bound = initialBound, bestMiss = HUGE_VAL;
  double tooMany = 0, tooFew = HUGE_VAL;  // bracket: bounds giving more / fewer tets than wanted
  for (int attempt = 1; attempt <= 12; ++attempt) {
    Stuffing made = run(bound);
    const double count = std::max<double>(1, made.mesh.tets.size());
    const double miss = std::abs(count - target) / target;
    if (miss < bestMiss) {
      bestMiss = miss;
      best.mesh = std::move(made.mesh);
      best.dropped = made.dropped;
      best.maxVolume = bound;
    }
    best.runs = attempt;
    if (miss <= aim) break;
    (count > target ? tooMany : tooFew) = bound;
    const double next = bound * std::clamp(count / target, 0.1, 10.0);
    const bool bracketed = tooMany > 0 && tooFew < HUGE_VAL;
    bound = bracketed && !(next > tooMany && next < tooFew) ? std::sqrt(tooMany * tooFew) : next;
  }
  return best;
}

Tetrahedralisation builtin(const TriMesh& surface, double volume, const TetrahedraliseOptions& options) {
  // A BCC lattice of cube edge h has tets of volume h^3 / 12.
  auto run = [&](double bound) {
    if (options.stop && options.stop()) throw Stopped("stopped while meshing");
    return stuffIsosurface(surface, {std::cbrt(12 * bound), options.preserveVolume});
  };
  // Runs are cheap, so aim closer than the tolerance asks.
  if (options.targetTets > 0)
    return searchCount(run, double(options.targetTets), volume / double(options.targetTets),
                       options.countTolerance / 3);
  Tetrahedralisation r;
  r.maxVolume = options.maxVolume > 0 ? options.maxVolume : volume / 1000;
  Stuffing made = run(r.maxVolume);
  r.mesh = std::move(made.mesh);
  r.dropped = made.dropped;
  r.runs = 1;
  return r;
}

Tetrahedralisation tetgen(const TriMesh& surface, double volume, const TetrahedraliseOptions& options) {
  if (options.targetTets == 0) {
    Tetrahedralisation r;
    r.maxVolume = options.maxVolume;
    r.radiusEdge = options.radiusEdge;
    r.mesh = runTetGen(surface, r.maxVolume, r.radiusEdge, options);
    r.runs = 1;
    return r;
  }
  // The fewest tets a quality bound allows come without a volume bound; relax the quality until
  // that floor is below the target.
  const double target = static_cast<double>(options.targetTets);
  int runs = 0;
  Tetrahedralisation floor;
  for (double quality : {options.radiusEdge, std::max(options.radiusEdge, 2.0), 0.0}) {
    if (quality != 0 && quality < options.radiusEdge) continue;
    floor.mesh = runTetGen(surface, 0, quality, options);
    floor.radiusEdge = quality;
    floor.runs = ++runs;
    if (double(floor.mesh.tets.size()) <= target * (1 + options.countTolerance)) break;
    if (quality == 0) return floor;  // the target is below what the surface needs
  }
  if (double(floor.mesh.tets.size()) >= target * (1 - options.countTolerance)) return floor;
  auto run = [&](double bound) { return Stuffing{runTetGen(surface, bound, floor.radiusEdge, options), {}}; };
  Tetrahedralisation r = searchCount(run, target, 3 * volume / target, options.countTolerance);
  r.radiusEdge = floor.radiusEdge;
  r.runs += runs;
  // A volume bound also switches on TetGen's default quality bound, so without one the count can
  // jump past the target: then the unbounded floor may still be the closest.
  const auto miss = [&](const TetMesh& m) { return std::abs(double(m.tets.size()) - target); };
  if (miss(floor.mesh) < miss(r.mesh)) {
    floor.runs = r.runs;
    return floor;
  }
  return r;
}

}  // namespace

std::string droppedMessage(const Tetrahedralisation& r) {
  const DroppedPieces& d = r.dropped;
  if (d.pieces == 0) return "";
  return fmt::format(
      "the mesher dropped {} loose or edge-joined fragment{} of {} tets ({:.2g}% of the volume): a part thinner than "
      "its lattice cell ({:.3g} across) came out in pieces; more tets keep it",
      d.pieces, d.pieces == 1 ? "" : "s", d.tets, 100 * d.share, std::cbrt(12 * r.maxVolume));
}

Tetrahedralisation tetrahedralise(const TriMesh& surface, const TetrahedraliseOptions& options) {
  if (!(options.maxVolume >= 0) || !std::isfinite(options.maxVolume))
    throw Error(fmt::format("the largest tet volume must be positive (got {})", options.maxVolume));
  if (!(options.countTolerance > 0))
    throw Error(fmt::format("the count tolerance must be positive (got {})", options.countTolerance));
  if (options.mesher == Mesher::TetGen && !(options.radiusEdge == 0 || options.radiusEdge >= 1.0))
    throw Error(
        fmt::format("TetGen's radius-edge bound must be at least 1, or 0 for none (got {})", options.radiusEdge));
  requireClosedSurface(surface);
  const double volume = enclosedVolume(surface);
  Tetrahedralisation result =
      options.mesher == Mesher::TetGen ? tetgen(surface, volume, options) : builtin(surface, volume, options);
  if (result.mesh.tets.empty())
    throw Error(options.targetTets > 0
                    ? fmt::format("{} produced no tets: {} {} too few for this surface (its tets would be as big as "
                                  "the body); ask for more, a few hundred at least",
                                  toString(options.mesher), options.targetTets, options.targetTets == 1 ? "is" : "are")
                    : fmt::format("{} produced no tets: the largest tet volume {:.4g} is not far enough below the "
                                  "body's volume {:.4g}; give a smaller one",
                                  toString(options.mesher), result.maxVolume, volume));
  return result;
}

}  // namespace vrd
