#include "vrdeform/haptics/haptic_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "vrdeform/error.h"

namespace vrd {
namespace {

float bodyMass(const World& world, BodyId id) {
  const Body& b = world.body(id);
  double mass = 0.0;
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
    if (const float w = world.particles().x[i].w; w > 0.0f) mass += 1.0 / w;
  return float(mass);
}

}  // namespace

void validateHapticSettings(const HapticSettings& settings) {
  const HapticSignalSettings& s = settings.signal;
  const auto positive = [](float v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0f)) throw Error(fmt::format("haptics: {} must be positive, got {}", name, v));
  };
  const auto unit = [](float v, const char* name) {
    if (!(v >= 0.0f && v <= 1.0f)) throw Error(fmt::format("haptics: {} must be in [0, 1], got {}", name, v));
  };
  positive(s.tauContact, "tauContact");
  positive(s.tauFingerContact, "tauFingerContact");
  positive(s.tauVolume, "tauVolume");
  positive(s.tauStrain, "tauStrain");
  unit(s.betaContact, "betaContact");
  unit(s.betaVolume, "betaVolume");
  unit(s.betaStrain, "betaStrain");
  if (std::abs(s.betaVolume + s.betaStrain - 1.0f) > 1e-4f)
    throw Error(fmt::format("haptics: betaVolume + betaStrain must be 1, got {}", s.betaVolume + s.betaStrain));
  if (!(std::isfinite(s.epsilon) && s.epsilon >= 0.0f))
    throw Error(fmt::format("haptics: epsilon must be finite and >= 0, got {}", s.epsilon));
  if (!(s.alphaT > 0.0f && s.alphaT <= 1.0f))
    throw Error(fmt::format("haptics: alphaT must be in (0, 1], got {}", s.alphaT));
  if (!(settings.maxChangePerMs > 0.0f))
    throw Error(fmt::format("haptics: maxChangePerMs must be positive, got {}", settings.maxChangePerMs));
  validateBaselineSettings(settings.baseline);
}

HapticModel::HapticModel(const HapticSettings& settings) : settings_(settings) { validateHapticSettings(settings); }

void HapticModel::gatherTets(const World& world) {
  // Algorithm 2, lines 25-31: the tet centroids c_j and signals f_j (eqs. 41-42), once per step.
  std::size_t count = 0;
  for (BodyId id = 0; id < world.bodyCount(); ++id)
    if (world.body(id).state == BodyState::Active) count += world.body(id).model->tets.size();
  tets_.resize(count);
  std::size_t first = 0;
  for (BodyId id = 0; id < world.bodyCount(); ++id) {
    const Body& b = world.body(id);
    if (b.state != BodyState::Active) continue;
    const Point* x = world.particles().x.data() + b.firstParticle;
    const std::size_t n = b.model->tets.size();
    for (std::size_t j = 0; j < n; ++j) {
      const Tet& t = b.model->tets[j];
      tets_.setCentroid(first + j, 0.25f * (x[t[0]].pos + x[t[1]].pos + x[t[2]].pos + x[t[3]].pos));
    }
    tetSignals(b.volumeLambda, b.strainLambda.values(), settings_.signal, std::span(tets_.f).subspan(first, n));
    first += n;
  }
}

float HapticModel::inverseDistanceSignal(const Vec3& centre) const {
  return volumeStrainSignal(tets_, centre, settings_.signal.epsilon);
}

const HapticFrame& HapticModel::update(const World& world, const HandRig& rig, const Grasp& grasp) {
  const HapticSignalSettings& s = settings_.signal;
  const float maxStep = settings_.maxChangePerMs * world.settings().timeStep * 1e3f;
  const float radius = rig.settings().geometry.fingertipRadius;
  // F_VS is needed only while something touches or holds the body: gather the tets then, once.
  bool gathered = false;
  const auto volumeStrain = [&](const Vec3& centre) {
    if (!gathered) gatherTets(world), gathered = true;
    return inverseDistanceSignal(centre);
  };

  std::size_t handContacts = 0;
  float handLambda = 0.0f;
  int pinching = 0;
  for (int f = 0; f < kFingerCount; ++f) pinching += grasp.pinching(Finger(f));

  for (int f = 0; f < kFingerCount; ++f) {
    FingerHaptics& out = frame_.fingers[f];
    if (!rig.has(Finger(f))) {
      out = {};
      continue;
    }
    const FingertipId tip = rig.fingertip(Finger(f));
    const Vec3 centre = world.fingertip(tip).center;
    const std::size_t count = world.fingertipContactCount(tip);
    const float lambdaSum = world.fingertipLambdaSum(tip);
    handContacts += count;
    handLambda += lambdaSum;
    const bool holding = grasp.pinching(Finger(f));

    // Eq. 43 for this finger alone: its contacts (summed, not averaged: one set of size 1), its
    // position as the grasp centre.
    out.raw = rawHapticForce(holding, count, normalisedContact(lambdaSum, count > 0 ? 1 : 0, s.tauFingerContact),
                             count > 0 || holding ? volumeStrain(centre) : 0.0f, s);
    out.force = limitChange(out.force, smoothHapticForce(out.force, out.raw, s.alphaT), maxStep);
    const Vec3 push = world.fingertipForce(tip);  // on the body: into it
    // The indentation, along the first push of this touch: the surface's normal where it began
    // (later pushes tilt with friction and the body's give).
    Touch& touch = touches_[f];
    if (count == 0) touch = {};
    if (count > 0 && !touch.began) touch = {true, centre, Vec3::Zero()};
    if (const float n = push.norm(); count > 0 && touch.along.isZero() && n > 0.0f && std::isfinite(n))
      touch.along = push / n;
    out.depth = std::max(0.0f, (centre - touch.at).dot(touch.along));
    out.contacts = count;

    if (!holding)
      out.newtons = push.norm();
    else if (grasp.settings().mode == GraspMode::Local)
      out.newtons = grasp.holdForce(world, Finger(f)).norm();
    else  // eq. 35 prescribes the body: the hand carries its weight, shared by the pinching fingers
      out.newtons = bodyMass(world, grasp.body()) * world.settings().gravity.norm() / float(pinching);
    if (!std::isfinite(out.newtons)) out.newtons = 0.0f;

    out.baseline =
        baselineForce(count > 0 || holding, proxyDistance(world.colliders(), centre, radius), settings_.baseline);
  }

  // Algorithm 2 as written: one contact set for the whole hand, p_g the mean fingertip position.
  const bool grasping = grasp.active();
  frame_.paperRaw = rawHapticForce(grasping, handContacts, normalisedContact(handLambda, handContacts, s.tauContact),
                                   handContacts > 0 || grasping ? volumeStrain(rig.meanFingertip()) : 0.0f, s);
  frame_.paper = limitChange(frame_.paper, smoothHapticForce(frame_.paper, frame_.paperRaw, s.alphaT), maxStep);
  return frame_;
}

}  // namespace vrd
