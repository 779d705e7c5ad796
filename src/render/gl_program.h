#pragma once
// A linked GLSL program (vertex + fragment) and its uniforms by name. Internal to the renderer.

#include <epoxy/gl.h>

#include <string>

#include "vrdeform/math/types.h"

namespace vrd {

class GlProgram {
 public:
  /// Compiles and links; throws vrd::Error with the driver's log.
  GlProgram(const char* vertexSource, const char* fragmentSource);
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  void use() const { glUseProgram(id_); }
  GLint uniform(const char* name) const { return glGetUniformLocation(id_, name); }
  void set(const char* name, int v) const { glUniform1i(uniform(name), v); }
  void set(const char* name, float v) const { glUniform1f(uniform(name), v); }
  void set(const char* name, const Vec3& v) const { glUniform3fv(uniform(name), 1, v.data()); }
  void set(const char* name, const Eigen::Matrix4f& m) const {
    glUniformMatrix4fv(uniform(name), 1, GL_FALSE, m.data());
  }
  void set(const char* name, const Mat3& m) const { glUniformMatrix3fv(uniform(name), 1, GL_FALSE, m.data()); }

 private:
  GLuint id_ = 0;
};

}  // namespace vrd
