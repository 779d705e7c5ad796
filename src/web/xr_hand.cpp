#include "vrdeform/web/xr_hand.h"

#include <algorithm>
#include <cmath>

namespace vrd {
namespace {

constexpr float kTrailing = 2.2f;  // radii between the index and each trailing finger

float unit(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; }

// A controller pointing straight down with its up along +x: the pinch closes along x, as the
// scenes' scripted grasps do.
const Eigen::Quaternionf kPointingDown(0.5f, -0.5f, -0.5f, -0.5f);

HandFrame pinch(const XrPose& ray, float closure, const XrHandSettings& s, float r) {
  HandFrame f;
  f.direct = true;
  const Eigen::Matrix3f R = ray.orientation.toRotationMatrix();
  const Vec3 ahead = -R.col(2), up = R.col(1);
  const Vec3 middle = ray.position + s.reach * ahead;
  const float gap = s.openGap + (s.closedGap - s.openGap) * unit(closure);
  const float half = 0.5f * gap + r;
  const Vec3 index = middle + half * up;
  f.fingertips[int(Finger::Thumb)] = middle - half * up;
  f.fingertips[int(Finger::Index)] = index;
  for (int k = 1; k <= 3; ++k) f.fingertips[int(Finger::Index) + k] = index - float(k) * kTrailing * r * ahead;
  return f;
}

}  // namespace

HandFrame xrParkedFrame(const XrHandSettings& settings, float fingertipRadius) {
  XrPose ray;
  ray.orientation = kPointingDown;
  ray.position = settings.park + Vec3(0.0f, settings.reach, 0.0f);
  return pinch(ray, 0.0f, settings, fingertipRadius);
}

HandFrame xrHandFrame(const XrInput& input, const XrHandSettings& settings, float fingertipRadius,
                      std::optional<float> closure) {
  switch (input.source) {
    case XrSource::Controller:
      return pinch(input.ray, closure ? *closure : input.trigger, settings, fingertipRadius);
    case XrSource::Hand: {
      HandFrame f;
      f.direct = true;
      f.fingertips = input.tips;  // a NaN tip keeps its fingertip where it was (HandRig::apply)
      return f;
    }
    case XrSource::None:
      break;
  }
  return xrParkedFrame(settings, fingertipRadius);
}

}  // namespace vrd
