#include "segmesh_render/detail/framebuffers.hpp"

#include <stdexcept>

namespace segmesh::render {
namespace {

// Each deletes the object when there is one and leaves its name 0.
void delete_texture(GLuint& t) {
  if (t) glDeleteTextures(1, &t);
  t = 0;
}
void delete_renderbuffer(GLuint& r) {
  if (r) glDeleteRenderbuffers(1, &r);
  r = 0;
}
void delete_framebuffer(GLuint& f) {
  if (f) glDeleteFramebuffers(1, &f);
  f = 0;
}

void attach(GLenum point, Attachment a) {
  if (a.texture) glFramebufferTexture2D(GL_FRAMEBUFFER, point, GL_TEXTURE_2D, a.texture, 0);
  if (a.renderbuffer) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, point, GL_RENDERBUFFER, a.renderbuffer);
  }
}

}  // namespace

GLuint make_texture(GLenum internal, GLenum format, GLenum type, int w, int h) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

GLuint make_renderbuffer(GLenum internal, int w, int h) {
  GLuint r = 0;
  glGenRenderbuffers(1, &r);
  glBindRenderbuffer(GL_RENDERBUFFER, r);
  glRenderbufferStorage(GL_RENDERBUFFER, internal, w, h);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  return r;
}

GLuint make_framebuffer(std::initializer_list<Attachment> colors, Attachment depth) {
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  GLenum buffers[4];
  GLsizei n = 0;
  for (Attachment c : colors) {
    attach(GL_COLOR_ATTACHMENT0 + n, c);
    buffers[n] = GL_COLOR_ATTACHMENT0 + n;
    ++n;
  }
  glDrawBuffers(n, buffers);
  attach(GL_DEPTH_ATTACHMENT, depth);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("renderer: incomplete framebuffer");
  }
  return fbo;
}

void SceneTargets::ensure(int w, int h, int samples) {
  const int aw = w / samples, ah = h / samples;
  if (w == width && h == height && aw == ao_width && ah == ao_height) return;
  release();
  depth = make_texture(GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, w, h);
  normal = make_texture(GL_RGBA16F, GL_RGBA, GL_FLOAT, w, h);
  color = make_texture(GL_RGBA16F, GL_RGBA, GL_FLOAT, w, h);
  ao = make_texture(GL_R16F, GL_RED, GL_FLOAT, aw, ah);
  blurred_ao = make_texture(GL_R16F, GL_RED, GL_FLOAT, aw, ah);
  glBindTexture(GL_TEXTURE_2D, 0);
  prepass_fbo = make_framebuffer({{.texture = normal}}, {.texture = depth});
  color_fbo = make_framebuffer({{.texture = color}}, {.texture = depth});
  ao_fbo = make_framebuffer({{.texture = ao}});
  blur_fbo = make_framebuffer({{.texture = blurred_ao}});
  width = w;
  height = h;
  ao_width = aw;
  ao_height = ah;
}

void SceneTargets::release() {
  for (GLuint* f : {&prepass_fbo, &color_fbo, &ao_fbo, &blur_fbo}) delete_framebuffer(*f);
  for (GLuint* t : {&depth, &normal, &color, &ao, &blurred_ao}) delete_texture(*t);
  width = height = ao_width = ao_height = 0;
}

void IdTarget::ensure(int w, int h) {
  if (w == width && h == height) return;
  release();
  ids = make_texture(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, w, h);
  glBindTexture(GL_TEXTURE_2D, 0);
  depth = make_renderbuffer(GL_DEPTH_COMPONENT24, w, h);
  fbo = make_framebuffer({{.texture = ids}}, {.renderbuffer = depth});
  width = w;
  height = h;
}

void IdTarget::release() {
  delete_framebuffer(fbo);
  delete_texture(ids);
  delete_renderbuffer(depth);
  width = height = 0;
}

void ImageTarget::ensure(int w, int h) {
  if (w == width && h == height) return;
  release();
  color = make_renderbuffer(GL_RGBA8, w, h);
  fbo = make_framebuffer({{.renderbuffer = color}});
  width = w;
  height = h;
}

void ImageTarget::release() {
  delete_framebuffer(fbo);
  delete_renderbuffer(color);
  width = height = 0;
}

}  // namespace segmesh::render
