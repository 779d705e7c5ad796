#include "vrdeform/interact/hand.h"

#include <algorithm>
#include <cmath>

namespace vrd {

HandGeometry HandGeometry::average() {
  constexpr float kDeg = 3.14159265f / 180.0f;
  const Vec3 distal = Vec3::UnitX(), curl = -Vec3::UnitY();  // turning about -y takes +x towards +z
  const std::array<float, 3> fingerRange{90 * kDeg, 100 * kDeg, 70 * kDeg};
  HandGeometry h;
  // The thumb leaves the palm forwards and outwards and curls across it, about an axis tilted
  // towards the palm so that it meets the index finger.
  h.fingers[int(Finger::Thumb)] = {Vec3(0.03f, 0.035f, 0.01f),
                                   Vec3(0.6f, 0.8f, 0.0f).normalized(),
                                   Vec3(0.5f, -0.4f, -0.77f).normalized(),
                                   {0.045f, 0.032f, 0.028f},
                                   {50 * kDeg, 60 * kDeg, 70 * kDeg}};
  h.fingers[int(Finger::Index)] = {Vec3(0.095f, 0.025f, 0), distal, curl, {0.045f, 0.025f, 0.020f}, fingerRange};
  h.fingers[int(Finger::Middle)] = {Vec3(0.1f, 0.005f, 0), distal, curl, {0.050f, 0.030f, 0.022f}, fingerRange};
  h.fingers[int(Finger::Ring)] = {Vec3(0.095f, -0.015f, 0), distal, curl, {0.047f, 0.028f, 0.021f}, fingerRange};
  h.fingers[int(Finger::Little)] = {Vec3(0.085f, -0.033f, 0), distal, curl, {0.037f, 0.020f, 0.019f}, fingerRange};
  return h;
}

Vec3 fingertipPosition(const HandGeometry& hand, const HandPose& pose, Finger finger) {
  const FingerGeometry& f = hand.fingers[int(finger)];
  const float raw = pose.closure[int(finger)];
  const float c = std::isfinite(raw) ? std::clamp(raw, 0.0f, 1.0f) : 0.0f;
  Vec3 tip = f.knuckle;
  float angle = 0.0f;
  for (int k = 0; k < 3; ++k) {
    angle += c * f.maxAngle[k];  // each joint adds to the bend of the segments after it
    tip += f.phalanx[k] * (Eigen::AngleAxisf(angle, f.bendAxis) * f.direction);
  }
  return pose.wrist * tip;
}

}  // namespace vrd
