#pragma once
// An OpenGL 3.3 core context with no window and no display: EGL on Mesa's surfaceless platform
// (EGL_MESA_platform_surfaceless), e.g. llvmpipe on a server. Rendering goes into a Framebuffer.

#include <string>

namespace vrd {

class HeadlessContext {
 public:
  /// Creates the context and makes it current on this thread. Throws vrd::Error saying what is
  /// missing when EGL, its surfaceless platform or an OpenGL 3.3 core context is unavailable.
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  /// Makes the context current on the calling thread (it is current on the creating one).
  void makeCurrent();
  /// GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  std::string description() const;

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
};

}  // namespace vrd
