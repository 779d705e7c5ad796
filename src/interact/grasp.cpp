#include "vrdeform/interact/grasp.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <optional>

#include "vrdeform/error.h"

namespace vrd {
namespace {

std::optional<BodyId> bodyOf(const World& world, Index particle) {
  for (BodyId b = 0; b < world.bodyCount(); ++b) {
    const Body& body = world.body(b);
    if (particle >= body.firstParticle && particle < body.firstParticle + body.particleCount) return b;
  }
  return std::nullopt;
}

// The body a fingertip pushed in the last substep (the first one found), if any.
std::optional<BodyId> touchedBody(const World& world, FingertipId tip) {
  const auto& contacts = world.fingertipContacts();
  const auto& lambda = world.fingertipContactLambda();
  for (std::size_t c = 0; c < contacts.size(); ++c)
    if (contacts[c].fingertip == tip && lambda[c] > 0.0f) return bodyOf(world, contacts[c].particle);
  const auto& triangles = world.fingertipTriangleContacts();
  const auto& triangleLambda = world.fingertipTriangleContactLambda();
  for (std::size_t c = 0; c < triangles.size(); ++c)
    if (triangles[c].fingertip == tip && triangleLambda[c] > 0.0f) return bodyOf(world, triangles[c].i[0]);
  return std::nullopt;
}

}  // namespace

void validateGraspSettings(const GraspSettings& s) {
  const auto check = [](float v, const char* name) {
    if (!(std::isfinite(v) && v >= 0.0f))
      throw Error(fmt::format("grasp: {} must be finite and >= 0, got {}", name, v));
  };
  check(s.releaseOpening, "releaseOpening");
  check(s.closingSpeed, "closingSpeed");
  check(s.holdReach, "holdReach");
  check(s.holdCompliance, "holdCompliance");
}

Grasp::Grasp(const GraspSettings& settings) : settings_(settings) { validateGraspSettings(settings); }

Vec3 Grasp::pinchCentre(const HandRig& rig) const {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (int f = 0; f < kFingerCount; ++f)
    if (pinching_[f]) sum += rig.target(Finger(f)), ++n;
  return sum / float(n);
}

void Grasp::update(World& world, const HandRig& rig) {
  std::array<float, kFingerCount> aperture = noApertures();
  if (rig.has(Finger::Thumb))
    for (int f = 1; f < kFingerCount; ++f)
      if (rig.has(Finger(f))) aperture[f] = (rig.target(Finger(f)) - rig.target(Finger::Thumb)).norm();

  if (active_) {
    if (aperture[int(partner_)] > startAperture_ + settings_.releaseOpening)
      release(world, rig);
    else
      follow(world, rig);
  } else if (settings_.enabled && rig.has(Finger::Thumb)) {
    // Thumb and at least one other finger on the same body, closing (Algorithm 2, line 3).
    const std::optional<BodyId> body = touchedBody(world, rig.fingertip(Finger::Thumb));
    const float minClosing = settings_.closingSpeed * world.settings().timeStep;
    std::array<bool, kFingerCount> pinching{};
    bool any = false;
    for (int f = 1; f < kFingerCount && body; ++f) {
      if (!rig.has(Finger(f)) || touchedBody(world, rig.fingertip(Finger(f))) != body) continue;
      pinching[f] = aperture[f] < lastAperture_[f] - minClosing;
      any |= pinching[f];
    }
    if (any) {
      pinching[int(Finger::Thumb)] = true;
      begin(world, rig, *body, pinching);
    }
  }
  lastAperture_ = aperture;
}

void Grasp::begin(World& world, const HandRig& rig, BodyId body, const std::array<bool, kFingerCount>& pinching) {
  active_ = true;
  body_ = body;
  pinching_ = pinching;
  partner_ = Finger::Index;
  float closest = std::numeric_limits<float>::infinity();
  for (int f = 1; f < kFingerCount; ++f) {
    const float gap = (rig.target(Finger(f)) - rig.target(Finger::Thumb)).norm();
    if (pinching[f] && gap < closest) closest = gap, partner_ = Finger(f);
  }
  startAperture_ = closest;

  const Body& b = world.body(body);
  const Particles& particles = world.particles();
  if (settings_.mode == GraspMode::Paper) {
    // Algorithm 2, line 5: cache x_ref; line 13: N(r) is empty while grasping.
    reference_.assign(b.particleCount, Vec3::Zero());
    for (Index i = 0; i < b.particleCount; ++i) reference_[i] = particles.x[b.firstParticle + i].pos;
    anchor_ = pinchCentre(rig);
    lastShift_.setZero();
    for (int f = 0; f < kFingerCount; ++f)
      if (rig.has(Finger(f))) world.setFingertipEnabled(rig.fingertip(Finger(f)), false);
  } else {
    // Hold what lies within reach of each pinching fingertip, or its nearest particle.
    startWrist_ = Eigen::Quaternionf(rig.wrist().linear());
    const Eigen::Quaternionf toWrist = startWrist_.conjugate();
    const float reach = settings_.holdReach * rig.settings().geometry.fingertipRadius;
    std::vector<bool> held(b.particleCount, false);
    for (int f = 0; f < kFingerCount; ++f) {
      if (!pinching[f]) continue;
      const FingertipId tip = rig.fingertip(Finger(f));
      const Vec3 centre = world.fingertip(tip).center;
      Index nearest = 0;
      float nearestDistance = std::numeric_limits<float>::infinity();
      auto hold = [&](Index i) {
        const Index g = b.firstParticle + i;
        if (held[i] || particles.x[g].w == 0.0f) return;
        held[i] = true;
        const Vec3& x = particles.x[g].pos;
        holds_.push_back({world.attach(g, x, settings_.holdCompliance), Finger(f), toWrist * (x - centre)});
      };
      const std::size_t before = holds_.size();
      for (Index i = 0; i < b.particleCount; ++i) {
        const float d = (particles.x[b.firstParticle + i].pos - centre).norm();
        if (d <= reach) hold(i);
        if (d < nearestDistance && particles.x[b.firstParticle + i].w > 0.0f) nearestDistance = d, nearest = i;
      }
      if (holds_.size() == before && std::isfinite(nearestDistance)) hold(nearest);
      world.setFingertipEnabled(tip, false);
    }
  }
  follow(world, rig);
}

void Grasp::follow(World& world, const HandRig& rig) {
  if (settings_.mode == GraspMode::Paper) {
    // Eq. 35: x_j <- x_j^ref + dp_hand, moving with the hand's velocity so that gravity does not
    // build up speed in a body whose positions are overwritten every step.
    const Vec3 shift = pinchCentre(rig) - anchor_;
    const Vec3 velocity = (shift - lastShift_) / world.settings().timeStep;
    lastShift_ = shift;
    const Body& b = world.body(body_);
    Particles& particles = world.particles();
    for (Index i = 0; i < b.particleCount; ++i) {
      const Index g = b.firstParticle + i;
      particles.x[g].pos = reference_[i] + shift;
      particles.v[g] = velocity;
    }
    return;
  }
  const Eigen::Quaternionf turn(rig.wrist().linear());
  for (const Hold& h : holds_) world.moveAttachment(h.attachment, rig.target(h.finger) + turn * h.offset);
}

void Grasp::release(World& world, const HandRig& rig) {
  if (!active_) return;
  for (const Hold& h : holds_) world.detach(h.attachment);
  holds_.clear();
  reference_.clear();
  for (int f = 0; f < kFingerCount; ++f)
    if (rig.has(Finger(f))) world.setFingertipEnabled(rig.fingertip(Finger(f)), true);
  active_ = false;
  pinching_.fill(false);
}

Vec3 Grasp::holdForce(const World& world, Finger f) const {
  Vec3 sum = Vec3::Zero();
  for (const Hold& h : holds_)
    if (h.finger == f) sum += world.attachmentForce(h.attachment);
  return sum;
}

}  // namespace vrd
