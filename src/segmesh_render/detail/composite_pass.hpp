// The composition pass: the shaded colour (SceneTargets::color, linear and premultiplied at the
// internal size) into the caller's framebuffer and viewport — exposure, tone mapping (ACES fit),
// the background gradient under the parts, the average of the supersamples, sRGB encoding.
//
// Why: the one pass that writes the caller's target, so the target needs no depth buffer and
// keeps everything outside the viewport as it was.
// Guarantees: every pixel of the viewport is written, opaque; the background runs from
// RenderOptions::background_bottom at the viewport's lower edge to background_top at its upper
// edge (sRGB colours, blended in linear light). Cost: one full-screen pass at the target's size,
// samples^2 texel reads per pixel. Needs a current OpenGL 3.3 core context, also for the
// destructor.
#pragma once

#include <epoxy/gl.h>

#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::render {

class CompositePass {
 public:
  CompositePass();  // links the program
  ~CompositePass();
  CompositePass(const CompositePass&) = delete;
  CompositePass& operator=(const CompositePass&) = delete;

  // Composes `color` (a texture of vp.width * samples x vp.height * samples) into `viewport` of
  // framebuffer `target`, bound for drawing. Leaves depth testing, clip distance 0 and the
  // scissor test off.
  void render(GLuint color, int samples, const RenderOptions& o, GLuint target, const Viewport& vp,
              const FullscreenTriangle& triangle);

 private:
  GLuint composite_ = 0;  // program
};

}  // namespace segmesh::render
