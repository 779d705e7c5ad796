#include "vrdeform/haptics/calibration.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "vrdeform/error.h"

namespace vrd {
namespace {

Vec3 centroid(const World& world, BodyId id) {
  const Body& b = world.body(id);
  Vec3 sum = Vec3::Zero();
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) sum += world.particles().x[i].pos;
  return sum / float(std::max<Index>(b.particleCount, 1));
}

// Inverse-distance-weighted mean of |lambda^V| and ||lambda^S|| around `centre` (eq. 43's weights).
std::pair<double, double> weightedMultipliers(const World& world, BodyId id, const Vec3& centre, float epsilon,
                                              TetSignals& tets) {
  const Body& b = world.body(id);
  const Point* x = world.particles().x.data() + b.firstParticle;
  double v = 0.0, s = 0.0, weights = 0.0;
  tets.resize(b.model->tets.size());
  for (std::size_t j = 0; j < b.model->tets.size(); ++j) {
    const Tet& t = b.model->tets[j];
    const Vec3 centroid = 0.25f * (x[t[0]].pos + x[t[1]].pos + x[t[2]].pos + x[t[3]].pos);
    tets.setCentroid(j, centroid);
    const double w = 1.0 / ((centroid - centre).norm() + epsilon);
    if (j < b.volumeLambda.size()) v += w * std::abs(b.volumeLambda[j]);
    if (j < b.strainLambda.size()) {
      float sq = 0.0f;
      for (float l : b.strainLambda[j]) sq += l * l;
      s += w * std::sqrt(sq);
    }
    weights += w;
  }
  return weights > 0.0 ? std::pair{v / weights, s / weights} : std::pair{0.0, 0.0};
}

}  // namespace

HapticCalibration calibrateHaptics(const World& original, BodyId body, const HapticSignalSettings& base,
                                   const CalibrationSettings& settings) {
  if (body >= original.bodyCount()) throw Error(fmt::format("calibration: no body {}", body));
  if (!(settings.radius > 0.0f && std::isfinite(settings.radius)) || !(settings.depth >= 0.0f) ||
      !(settings.duration > 0.0f) || !(settings.contactTarget > 0.0f) ||
      !(settings.volumeStrainTarget > 0.0f && settings.volumeStrainTarget < 1.0f))
    throw Error("calibration: radius, duration and targets must be positive (volumeStrainTarget < 1), depth >= 0");
  World world = original;
  for (FingertipId f = 0; f < world.fingertipCount(); ++f) world.setFingertipEnabled(f, false);

  const Vec3 g = world.settings().gravity;
  const Vec3 down = g.norm() > 0.0f ? Vec3(g.normalized()) : Vec3(-Vec3::UnitY());
  const Body& b = world.body(body);
  Vec3 point = Vec3::Constant(std::numeric_limits<float>::quiet_NaN());
  if (settings.point) {
    point = *settings.point;
  } else {
    float highest = -std::numeric_limits<float>::infinity();
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
      if (const float up = -down.dot(world.particles().x[i].pos); up > highest)
        highest = up, point = world.particles().x[i].pos;
  }
  if (!isFinite(point)) throw Error("calibration: the poke point is not finite");
  const float r = settings.radius;
  const float depth = settings.depth > 0.0f ? settings.depth : r;
  const Vec3 start = point - down * (1.5f * r), end = point + down * (depth - r);
  const FingertipId tip = world.addFingertip(start, r, 0.0f, settings.contact);
  world.setFingertipFriction(tip, settings.friction);
  const Vec3 before = centroid(world, body);

  const int loading = std::max(1, int(std::lround(settings.duration / world.settings().timeStep)));
  for (int k = 1; k <= loading + loading / 2; ++k) {
    world.moveFingertip(tip, start + std::min(1.0f, float(k) / float(loading)) * (end - start));
    world.step();
    if (settings.stop && settings.stop()) throw Stopped("stopped while calibrating the haptics");
  }
  const float sag = down.dot(centroid(world, body) - before);
  if (sag > 0.5f * depth)
    throw Error(fmt::format(
        "calibration: body {} gave way as a whole ({:.1f} mm for a {:.1f} mm poke): it is not at rest; rest it on "
        "something or pin it, let it settle longer, or check its size (a mesh in millimetres needs scale = 0.001)",
        body, 1e3f * sag, 1e3f * depth));

  const std::size_t count = world.fingertipContactCount(tip);
  if (count == 0) {
    float speed = 0.0f;
    for (Index i = world.body(body).firstParticle; i < world.body(body).firstParticle + world.body(body).particleCount;
         ++i)
      speed = std::max(speed, world.particles().v[i].norm());
    throw Error(fmt::format(
        "calibration: the poke made no contact with body {}{}", body,
        speed > 0.05f ? fmt::format(": the body is still moving (up to {:.3g} m/s), so it left the point poked; let it "
                                    "come to rest first, or check its size (a mesh in millimetres needs scale = 0.001)",
                                    speed)
        : settings.friction.staticFriction > 0.0f
            ? ""
            : " (a frictionless fingertip can push a round body out from under it: give the hand friction)"));
  }
  HapticCalibration out;
  out.signal = base;
  out.point = point;
  out.direction = down;
  out.depth = depth;
  out.force = world.fingertipForce(tip).norm();
  out.contacts = count;
  out.signal.tauContact = world.fingertipLambdaSum(tip) / float(count) / settings.contactTarget;
  out.signal.tauFingerContact = world.fingertipLambdaSum(tip) / settings.contactTarget;

  TetSignals tets;
  const auto [volume, strain] = weightedMultipliers(world, body, world.fingertip(tip).center, base.epsilon, tets);
  if (volume > 0.0 || strain > 0.0) {
    // F_VS falls as the tau grow together; bisect the common scale (in log space) to the target.
    const Body& poked = world.body(body);
    auto signalAt = [&](double scale) {
      HapticSignalSettings s = base;
      s.tauVolume = volume > 0.0 ? float(scale * volume) : base.tauVolume;
      s.tauStrain = strain > 0.0 ? float(scale * strain) : base.tauStrain;
      tetSignals(poked.volumeLambda, poked.strainLambda.values(), s, tets.f);
      return std::pair{s, volumeStrainSignal(tets, world.fingertip(tip).center, base.epsilon)};
    };
    double lo = std::log(1e-6), hi = std::log(1e6);
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      (signalAt(std::exp(mid)).second > settings.volumeStrainTarget ? lo : hi) = mid;
    }
    const HapticSignalSettings s = signalAt(std::exp(0.5 * (lo + hi))).first;
    out.signal.tauVolume = s.tauVolume;
    out.signal.tauStrain = s.tauStrain;
  }
  if (!(out.signal.tauContact > 0.0f && std::isfinite(out.signal.tauContact) && out.signal.tauFingerContact > 0.0f &&
        std::isfinite(out.signal.tauFingerContact) && out.signal.tauVolume > 0.0f &&
        std::isfinite(out.signal.tauVolume) && out.signal.tauStrain > 0.0f && std::isfinite(out.signal.tauStrain)))
    throw Error("calibration: the poke gave non-finite or zero multipliers");
  return out;
}

}  // namespace vrd
