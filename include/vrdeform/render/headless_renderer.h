#pragma once
// Renders a scene's snapshots into images with no window or display: a HeadlessContext, a
// Framebuffer of the image's size, and the scene posed and drawn as in the desktop viewer.

#include <string>

#include "vrdeform/render/framebuffer.h"
#include "vrdeform/render/headless_context.h"
#include "vrdeform/render/scene_renderer.h"

namespace vrd {

class HeadlessRenderer {
 public:
  /// `scene` must outlive the renderer. Throws vrd::Error when no headless OpenGL context can be
  /// made or for a size outside [1, 16384]. One per thread: it owns that thread's context.
  HeadlessRenderer(const BuiltScene& scene, int width, int height, int samples = 4);

  /// Poses the scene as `snapshot` has it and draws it.
  Image render(const Snapshot& snapshot, const OrbitCamera& camera, const RenderSettings& settings = {});

  /// The scene as last posed (at rest before the first render()).
  const PosedScene& posed() const { return posed_; }
  /// A camera framing the bodies as last posed.
  OrbitCamera framingCamera() const;
  /// The OpenGL implementation, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  std::string description() const { return context_.description(); }
  int width() const { return framebuffer_.width(); }
  int height() const { return framebuffer_.height(); }

 private:
  HeadlessContext context_;  // first: made before and destroyed after the GL objects below
  Framebuffer framebuffer_;
  PosedScene posed_;
  SceneRenderer renderer_;
};

}  // namespace vrd
