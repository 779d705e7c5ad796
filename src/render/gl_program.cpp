#include "gl_program.h"

#include <fmt/format.h>

#include <vector>

#include "vrdeform/error.h"

namespace vrd {
namespace {

GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0, length = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok) return shader;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(std::size_t(std::max(length, 1)));
  glGetShaderInfoLog(shader, GLsizei(log.size()), nullptr, log.data());
  glDeleteShader(shader);
  throw Error(fmt::format("renderer: the {} shader does not compile: {}",
                          type == GL_VERTEX_SHADER ? "vertex" : "fragment", log.data()));
}

}  // namespace

GlProgram::GlProgram(const char* vertexSource, const char* fragmentSource) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertexSource);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragmentSource);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0, length = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (ok) return;
  glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(std::size_t(std::max(length, 1)));
  glGetProgramInfoLog(id_, GLsizei(log.size()), nullptr, log.data());
  glDeleteProgram(id_);
  throw Error(fmt::format("renderer: the shaders do not link: {}", log.data()));
}

GlProgram::~GlProgram() { glDeleteProgram(id_); }

}  // namespace vrd
