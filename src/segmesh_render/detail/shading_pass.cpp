#include "segmesh_render/detail/shading_pass.hpp"

#include <algorithm>
#include <vector>

#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/detail/shaders.hpp"

namespace segmesh::render {

ShadingPass::ShadingPass() {
  shade_ = link_program(shaders::mesh_vertex, shaders::shade_fragment, "shade");
}

ShadingPass::~ShadingPass() {
  glDeleteProgram(shade_);
}

void ShadingPass::render(const Frame& f, const RenderOptions& o, int samples, bool ao,
                         const SceneTargets& targets) {
  glBindFramebuffer(GL_FRAMEBUFFER, targets.color_fbo);
  const float clear[4] = {0, 0, 0, 0};
  glClearBufferfv(GL_COLOR, 0, clear);
  if (ao) {
    glDepthFunc(GL_LEQUAL);  // the prepass laid the same depths (invariant gl_Position)
  } else {
    glClear(GL_DEPTH_BUFFER_BIT);
    glDepthFunc(GL_LESS);
  }
  glUseProgram(shade_);
  bind_samplers(shade_, {{"u_ao", ao ? targets.blurred_ao : 0}});
  set_uniform(shade_, "u_use_ao", ao ? 1 : 0);
  set_uniform(shade_, "u_ao_step", samples);
  set_uniform(shade_, "u_ao_strength", float(std::clamp(o.ao_strength, 0.0, 1.0)));
  set_uniform(shade_, "u_clipped", f.clipped ? 1 : 0);
  set_uniform(shade_, "u_hatch_period", float(8 * samples));
  const bool quality = o.color == ColorMode::quality;
  auto draw_items = [&](const std::vector<DrawItem>& items) {
    for (const DrawItem& d : items) {
      const Material& m = d.part->material;
      set_mesh_uniforms(shade_, f, d);
      set_uniform(shade_, "u_base_color", m.base_color.r, m.base_color.g, m.base_color.b);
      set_uniform(shade_, "u_metallic", m.metallic);
      set_uniform(shade_, "u_roughness", m.roughness);
      set_uniform(shade_, "u_opacity", d.opacity);
      set_uniform(shade_, "u_vertex_color", quality ? 1 : 0);
      set_uniform(shade_, "u_highlight", int(d.index) == o.selected ? 1.0f : 0.0f);
      draw_mesh(d);
    }
  };
  draw_items(f.opaque);
  if (!f.transparent.empty()) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);  // premultiplied
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    draw_items(f.transparent);
    glDisable(GL_CULL_FACE);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
}

}  // namespace segmesh::render
