#include "segmesh_render/detail/gl_state.hpp"

namespace segmesh::render {

SavedTarget save_target() {
  SavedTarget s;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s.draw);
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s.read);
  glGetIntegerv(GL_VIEWPORT, s.viewport);
  return s;
}

void restore_target(const SavedTarget& s) {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(s.draw));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(s.read));
  const GLint* viewport = s.viewport;
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_CLIP_DISTANCE0);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glUseProgram(0);
  glBindVertexArray(0);
  for (int unit = 2; unit >= 0; --unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, 0);
  }
}

}  // namespace segmesh::render
