#pragma once
// An off-screen render target (colour and depth, multisampled when asked) that reads back as an
// Image: where headless frames are drawn. Needs a current OpenGL 3.3 context.

#include "vrdeform/render/image.h"

namespace vrd {

class Framebuffer {
 public:
  /// Throws vrd::Error for a size outside [1, 16384] or an incomplete framebuffer.
  Framebuffer(int width, int height, int samples = 4);
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Makes it the target of the following draws, with its whole area as the viewport.
  void bind();
  /// Resolves the samples and reads the pixels (top row first).
  Image read();

 private:
  int width_, height_, samples_;
  unsigned draw_ = 0, resolve_ = 0;  // framebuffers (resolve_ only when multisampled)
  unsigned colour_ = 0, depth_ = 0, resolved_ = 0;
};

}  // namespace vrd
