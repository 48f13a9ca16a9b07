#include "segmesh_render/detail/composite_pass.hpp"

#include <cmath>

#include "segmesh_render/detail/shaders.hpp"

namespace segmesh::render {
namespace {

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

CompositePass::CompositePass() {
  composite_ = link_program(shaders::fullscreen_vertex, shaders::composite_fragment, "composite");
}

CompositePass::~CompositePass() {
  glDeleteProgram(composite_);
}

void CompositePass::render(GLuint color, int samples, const RenderOptions& o, GLuint target,
                           const Viewport& vp, const FullscreenTriangle& triangle) {
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
  glViewport(vp.x, vp.y, vp.width, vp.height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CLIP_DISTANCE0);
  glDisable(GL_SCISSOR_TEST);
  glUseProgram(composite_);
  bind_samplers(composite_, {{"u_color", color}});
  set_uniform(composite_, "u_samples", samples);
  set_uniform(composite_, "u_origin", float(vp.x), float(vp.y));
  set_uniform(composite_, "u_size", float(vp.width), float(vp.height));
  const Rgb& top = o.background_top;
  const Rgb& bottom = o.background_bottom;
  set_uniform(composite_, "u_background_top", srgb_to_linear(top.r), srgb_to_linear(top.g),
              srgb_to_linear(top.b));
  set_uniform(composite_, "u_background_bottom", srgb_to_linear(bottom.r), srgb_to_linear(bottom.g),
              srgb_to_linear(bottom.b));
  set_uniform(composite_, "u_exposure", float(o.exposure));
  triangle.draw(composite_);
}

}  // namespace segmesh::render
