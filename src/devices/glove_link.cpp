#include "vrdeform/devices/glove_link.h"

#include <fmt/format.h>

#include <thread>

#include "vrdeform/error.h"

namespace vrd {
namespace {

weart::ClientSettings clientSettings(const std::string& endpoint, const HandRigSettings& hand) {
  weart::ClientSettings cs = weart::parseEndpoint(endpoint);
  cs.thimbles.clear();
  for (int f = 0; f < kFingerCount; ++f)
    if (hand.fingers[f]) cs.thimbles.push_back(weart::pointOf(Finger(f)));
  return cs;
}

}  // namespace

Eigen::Isometry3f wristAbove(const Vec3& point, const HandGeometry& hand) {
  HandPose pose;
  pose.wrist.linear() = Eigen::AngleAxisf(1.5707963f, Vec3::UnitX()).toRotationMatrix();  // +z (palm) down
  pose.closure.fill(0.5f);
  const Vec3 reach = fingertipPosition(hand, pose, Finger::Index);  // wrist at the origin
  pose.wrist.translation() = point + Vec3(0.0f, 0.5f * hand.fingertipRadius, 0.0f) - reach;
  return pose.wrist;
}

std::string weartEndpointError(const std::string& endpoint) {
  try {
    weart::parseEndpoint(endpoint);
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

void printGloveNews(std::string_view line, bool error) { fmt::print(error ? stderr : stdout, "glove: {}\n", line); }

GloveLink::GloveLink(const std::string& endpoint, const HandRigSettings& hand, const Vec3& point, GloveNews news)
    : client_(clientSettings(endpoint, hand)), news_(std::move(news)) {
  const weart::ClientSettings& cs = client_.settings();
  client_.start();
  input_.emplace(client_, wristAbove(point, hand.geometry));
  name_ = fmt::format("glove {}:{}", cs.host, cs.port);
  news_(fmt::format("the WEART middleware at {}:{} (Ctrl-C stops; the glove is released)", cs.host, cs.port), false);
}

void GloveLink::reportEvents() {
  for (const weart::Event& e : client_.takeEvents()) news_(e.message, e.error);
}

std::optional<float> GloveLink::closure(Finger finger) const {
  const auto c = client_.closures();
  if (!c) return std::nullopt;
  return (*c)[int(finger)];
}

bool GloveLink::connected() const {
  const weart::State s = client_.state();
  return s == weart::State::Running || s == weart::State::Calibrating;
}

void GloveLink::afterStep(const HapticFrame& frame, double time) {
  std::array<float, kFingerCount> force{};
  for (int f = 0; f < kFingerCount; ++f) force[f] = frame.fingers[f].force;
  client_.publishForces(force);
  reportEvents();
  if (!start_)
    start_ = std::chrono::steady_clock::now() -
             std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(time));
  std::this_thread::sleep_until(
      *start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(time)));
}

}  // namespace vrd
