#include "vrdeform/render/headless_renderer.h"

#include <epoxy/gl.h>

namespace vrd {

HeadlessRenderer::HeadlessRenderer(const BuiltScene& scene, int width, int height, int samples)
    : framebuffer_(width, height, samples), posed_(scene), renderer_(posed_) {}

Image HeadlessRenderer::render(const Snapshot& snapshot, const OrbitCamera& camera, const RenderSettings& settings) {
  posed_.pose(snapshot, settings.colorMap);
  framebuffer_.bind();
  renderer_.draw(posed_, snapshot, camera, framebuffer_.width(), framebuffer_.height(), settings);
  return framebuffer_.read();
}

OrbitCamera HeadlessRenderer::framingCamera() const {
  OrbitCamera camera;
  camera.frame(posed_.bounds());
  return camera;
}

}  // namespace vrd
