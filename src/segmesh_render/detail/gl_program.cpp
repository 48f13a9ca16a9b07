#include "segmesh_render/detail/gl_program.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace segmesh::render {
namespace {

// How OpenGL reports the outcome of building a shader (compiling) or a program (linking): the
// same three calls, with different entry points and status.
struct BuildStep {
  GLenum status;                      // GL_COMPILE_STATUS or GL_LINK_STATUS
  PFNGLGETSHADERIVPROC get_iv;        // glGetShaderiv or glGetProgramiv
  PFNGLGETSHADERINFOLOGPROC get_log;  // glGetShaderInfoLog or glGetProgramInfoLog
  PFNGLDELETESHADERPROC destroy;      // glDeleteShader or glDeleteProgram
  const char* object;                 // "shader" or "program"
  const char* failure;                // "does not compile" or "does not link"
};

// Returns when `step` succeeded for `object`; otherwise deletes it and throws with the log.
void check_built(GLuint object, const BuildStep& step, const char* name) {
  GLint ok = 0;
  step.get_iv(object, step.status, &ok);
  if (ok) return;
  char log[4096] = {};
  step.get_log(object, sizeof log, nullptr, log);
  step.destroy(object);
  throw std::runtime_error(std::string("renderer: ") + step.object + " " + name + " " +
                           step.failure + ": " + log);
}

GLuint compile_shader(GLenum type, const char* source, const char* name) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  check_built(shader,
              {GL_COMPILE_STATUS, glGetShaderiv, glGetShaderInfoLog, glDeleteShader, "shader",
               "does not compile"},
              name);
  return shader;
}

}  // namespace

GLuint link_program(const char* vertex, const char* fragment, const char* name) {
  const GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex, name);
  const GLuint fs = compile_shader(GL_FRAGMENT_SHADER, fragment, name);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glBindAttribLocation(program, 0, "a_position");
  glBindAttribLocation(program, 1, "a_normal");
  glBindAttribLocation(program, 2, "a_color");
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  check_built(program,
              {GL_LINK_STATUS, glGetProgramiv, glGetProgramInfoLog, glDeleteProgram, "program",
               "does not link"},
              name);
  return program;
}

GLint uniform_location(GLuint p, const char* name) {
  return glGetUniformLocation(p, name);
}

void set_uniform(GLuint p, const char* n, int v) {
  glUniform1i(uniform_location(p, n), v);
}
void set_uniform(GLuint p, const char* n, float v) {
  glUniform1f(uniform_location(p, n), v);
}
void set_uniform(GLuint p, const char* n, float x, float y) {
  glUniform2f(uniform_location(p, n), x, y);
}
void set_uniform(GLuint p, const char* n, float x, float y, float z) {
  glUniform3f(uniform_location(p, n), x, y, z);
}
void set_uniform(GLuint p, const char* n, float x, float y, float z, float w) {
  glUniform4f(uniform_location(p, n), x, y, z, w);
}
void set_uniform(GLuint p, const char* n, const Mat4& m) {
  const auto f = to_float(m);
  glUniformMatrix4fv(uniform_location(p, n), 1, GL_FALSE, f.data());
}
void set_uniform(GLuint p, const char* n, const Mat3& m) {
  std::array<float, 9> f{};
  for (int i = 0; i < 9; ++i) f[i] = static_cast<float>(m[i]);
  glUniformMatrix3fv(uniform_location(p, n), 1, GL_FALSE, f.data());
}

void bind_samplers(GLuint p, std::initializer_list<Sampler> samplers) {
  int unit = 0;
  for (const Sampler& s : samplers) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, s.texture);
    set_uniform(p, s.name, unit);
    ++unit;
  }
}

FullscreenTriangle::FullscreenTriangle() {
  glGenVertexArrays(1, &vao_);
}
FullscreenTriangle::~FullscreenTriangle() {
  glDeleteVertexArrays(1, &vao_);
}

void FullscreenTriangle::draw(GLuint program) const {
  glUseProgram(program);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace segmesh::render
