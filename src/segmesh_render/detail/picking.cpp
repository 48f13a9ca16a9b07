#include "segmesh_render/detail/picking.hpp"

#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/detail/shaders.hpp"

namespace segmesh::render {

Picking::Picking() {
  id_ = link_program(shaders::mesh_vertex, shaders::id_fragment, "id");
}

Picking::~Picking() {
  glDeleteProgram(id_);
}

void Picking::render(const Frame& f, const std::array<int, 4>* scissor) {
  target_.ensure(f.width, f.height);
  glBindFramebuffer(GL_FRAMEBUFFER, target_.fbo);
  glViewport(0, 0, f.width, f.height);
  begin_mesh_pass(f);
  if (scissor) {
    glEnable(GL_SCISSOR_TEST);
    glScissor((*scissor)[0], (*scissor)[1], (*scissor)[2], (*scissor)[3]);
  }
  const GLuint zero[4] = {0, 0, 0, 0};
  glClearBufferuiv(GL_COLOR, 0, zero);
  glClear(GL_DEPTH_BUFFER_BIT);
  glDepthFunc(GL_LESS);
  glUseProgram(id_);
  for (const auto* items : {&f.opaque, &f.transparent}) {
    for (const DrawItem& d : *items) {
      set_mesh_uniforms(id_, f, d);
      glUniform1ui(uniform_location(id_, "u_id"), GLuint(d.index + 1));
      draw_mesh(d);
    }
  }
  glDisable(GL_SCISSOR_TEST);
}

std::vector<int32_t> Picking::read_all() const {
  const int width = target_.width, height = target_.height;
  std::vector<uint32_t> raw(size_t(width) * size_t(height));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target_.fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width, height, GL_RED_INTEGER, GL_UNSIGNED_INT, raw.data());
  std::vector<int32_t> ids(raw.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      ids[size_t(y) * width + x] = int32_t(raw[size_t(height - 1 - y) * width + x]) - 1;
    }
  }
  return ids;
}

std::optional<size_t> Picking::read_pixel(int x, int gl_y) const {
  GLuint value = 0;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target_.fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(x, gl_y, 1, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
  if (value == 0) return std::nullopt;
  return size_t(value - 1);
}

}  // namespace segmesh::render
