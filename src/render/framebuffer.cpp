#include "vrdeform/render/framebuffer.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>

#include "vrdeform/error.h"

namespace vrd {
namespace {

void storage(GLuint buffer, int samples, GLenum format, int w, int h) {
  glBindRenderbuffer(GL_RENDERBUFFER, buffer);
  if (samples > 1)
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
  else
    glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
}

void requireComplete(const char* what) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw Error(fmt::format("framebuffer: the {} target is incomplete (status 0x{:x})", what, status));
}

}  // namespace

Framebuffer::Framebuffer(int width, int height, int samples) : width_(width), height_(height) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw Error(fmt::format("framebuffer: size {}x{} is outside [1, 16384]", width, height));
  GLint maxSamples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  samples_ = std::clamp(samples, 1, std::max(1, maxSamples));
  glGenFramebuffers(1, &draw_);
  glGenRenderbuffers(1, &colour_);
  glGenRenderbuffers(1, &depth_);
  storage(colour_, samples_, GL_RGBA8, width, height);
  storage(depth_, samples_, GL_DEPTH_COMPONENT24, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  requireComplete("drawing");
  if (samples_ > 1) {  // multisampled pixels cannot be read directly: blit into a plain target first
    glGenFramebuffers(1, &resolve_);
    glGenRenderbuffers(1, &resolved_);
    storage(resolved_, 1, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolved_);
    requireComplete("resolve");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Framebuffer::~Framebuffer() {
  const GLuint framebuffers[] = {draw_, resolve_};
  const GLuint renderbuffers[] = {colour_, depth_, resolved_};
  glDeleteFramebuffers(2, framebuffers);
  glDeleteRenderbuffers(3, renderbuffers);
}

void Framebuffer::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_);
  glViewport(0, 0, width_, height_);
}

Image Framebuffer::read() {
  GLuint source = draw_;
  if (samples_ > 1) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = resolve_;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  Image bottomUp(width_, height_);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  // OpenGL's rows start at the bottom; images start at the top.
  Image image(width_, height_);
  const std::size_t row = std::size_t(width_) * 4;
  for (int y = 0; y < height_; ++y)
    std::copy_n(&bottomUp.rgba[std::size_t(height_ - 1 - y) * row], row, &image.rgba[std::size_t(y) * row]);
  return image;
}

}  // namespace vrd
