#include "vrdeform/interact/hand_actions.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "vrdeform/error.h"

namespace vrd {
namespace {

// Progress through [begin, begin + length] as 0..1 (a zero length jumps at once).
double ramp(double t, double begin, double length) {
  if (!(length > 0.0)) return t >= begin ? 1.0 : 0.0;
  return std::clamp((t - begin) / length, 0.0, 1.0);
}

// Progress u along a poke's profile. Minimum jerk, 10u^3 - 15u^4 + 6u^5 (Flash and Hogan 1985):
// it starts and stops with zero velocity and acceleration, so that a poke arriving at its depth
// does not strike the body and set it ringing under the held finger.
double along(PokeProfile profile, double u) {
  return profile == PokeProfile::Linear ? u : u * u * u * (10.0 + u * (6.0 * u - 15.0));
}

float mix(float a, float b, double u) { return a + float(u) * (b - a); }

HandFrame parked(const Vec3& target) {
  HandFrame f;
  f.direct = true;
  for (int i = 0; i < kFingerCount; ++i) f.fingertips[i] = target + Vec3(0.05f * float(i - 1), 1.0f, 0.0f);
  return f;
}

void check(const HandAction& a, std::size_t index) {
  const auto fail = [&](const char* what) { throw Error(fmt::format("hand action {}: {}", index + 1, what)); };
  if (!isFinite(a.target)) fail("the target is not finite");
  if (!(std::isfinite(a.start) && a.start >= 0.0)) fail("start must be finite and >= 0");
  for (double d : {a.approach, a.hold, a.release})
    if (!(std::isfinite(d) && d >= 0.0)) fail("approach, hold and release must be finite and >= 0");
  for (float v : {a.depth, a.width, a.lift})
    if (!(std::isfinite(v) && v >= 0.0f)) fail("depth, width and lift must be finite and >= 0");
  if (a.kind == ActionKind::Grasp && a.finger == Finger::Thumb)
    fail("a grasp pinches the thumb against another finger");
}

// Fingertip centres of action `a` at time t: the acting ones placed, the others parked.
HandFrame actionFrame(const HandAction& a, float r, double t) {
  HandFrame f = parked(a.target);
  // Height of a fingertip's centre whose lowest point is `depth` below the target.
  const auto centreY = [&](float depth) { return a.target.y() + r - depth; };
  const double t0 = a.start, t1 = t0 + a.approach, t2 = t1 + a.hold;
  if (a.kind == ActionKind::Poke) {
    float depth = -r;
    if (t < t1)
      depth = mix(-r, a.depth, along(a.profile, ramp(t, t0, a.approach)));
    else if (t < t2)
      depth = a.depth;
    else
      depth = mix(a.depth, -r, along(a.profile, ramp(t, t2, a.release)));
    f.fingertips[int(a.finger)] = Vec3(a.target.x(), centreY(depth), a.target.z());
    return f;
  }
  // Grasp: thumb on -x, the finger on +x; `gap` between the fingertips' surfaces.
  // It opens 2 cm wider than it started so that the grasp's hysteresis (GraspSettings) lets go.
  const float open = a.width > 0.0f ? a.width : 4.0f * r, closed = 0.5f * open, wide = open + 0.02f;
  float depth = -r, gap = open, lift = 0.0f;
  if (t < t1) {
    depth = mix(-r, a.depth, ramp(t, t0, 0.4 * a.approach));
    gap = mix(open, closed, ramp(t, t0 + 0.4 * a.approach, 0.6 * a.approach));
  } else if (t < t2) {
    depth = a.depth, gap = closed, lift = mix(0.0f, a.lift, ramp(t, t1, a.hold / 3.0));
  } else {
    // Lower half way (all the way would press the held body, which sags, into the ground), open
    // and rise: the body drops the rest.
    const double third = a.release / 3.0;
    lift = mix(a.lift, 0.5f * a.lift, ramp(t, t2, third));
    gap = mix(closed, wide, ramp(t, t2 + third, third));
    depth = mix(a.depth, -r, ramp(t, t2 + 2.0 * third, third));
  }
  const float half = 0.5f * gap + r, y = centreY(depth) + lift;
  f.fingertips[int(Finger::Thumb)] = Vec3(a.target.x() - half, y, a.target.z());
  f.fingertips[int(a.finger)] = Vec3(a.target.x() + half, y, a.target.z());
  return f;
}

}  // namespace

HandActionsInput::HandActionsInput(std::vector<HandAction> actions, float fingertipRadius, Aim aim)
    : radius_(fingertipRadius), aim_(std::move(aim)) {
  if (!(std::isfinite(radius_) && radius_ > 0.0f)) throw Error("hand actions: the fingertip radius must be positive");
  if (actions.empty()) throw Error("hand actions: none given");
  for (std::size_t i = 0; i < actions.size(); ++i) check(actions[i], i);
  given_.resize(actions.size());
  for (std::size_t i = 0; i < given_.size(); ++i) given_[i] = i;
  std::stable_sort(given_.begin(), given_.end(),
                   [&](std::size_t a, std::size_t b) { return actions[a].start < actions[b].start; });
  for (std::size_t i : given_) actions_.push_back(actions[i]);
  aimed_.assign(actions_.size(), false);
  for (std::size_t i = 1; i < actions_.size(); ++i)
    if (actions_[i].start < actions_[i - 1].end())
      throw Error(fmt::format("hand actions: an action starting at {:g} s overlaps one that ends at {:g} s",
                              actions_[i].start, actions_[i - 1].end()));
}

HandFrame HandActionsInput::frame(std::uint64_t, double t) {
  // The action under way, else the next one (its fingertips wait parked above it), else the last.
  // The actions end in order, so the search goes on from the last answer while time runs forward.
  if (next_ > 0 && t < actions_[next_ - 1].end()) next_ = 0;
  while (next_ < actions_.size() && !(t < actions_[next_].end())) ++next_;
  const std::size_t i = std::min(next_, actions_.size() - 1);
  HandAction& a = actions_[i];
  if (!(t >= a.start && t < a.end())) return parked(a.target);
  if (aim_ && !aimed_[i]) {
    aimed_[i] = true;
    if (const Vec3 target = aim_(given_[i]); isFinite(target)) a.target = target;
  }
  return actionFrame(a, radius_, t);
}

bool HandActionsInput::finished(std::uint64_t, double t) const { return !(t <= actions_.back().end()); }

}  // namespace vrd
