// The shading pass: a frame's opaque parts, then its transparent parts back to front, lit and
// coloured (renderer.hpp describes the lighting) into SceneTargets::color — linear light,
// premultiplied alpha, at the internal (supersampled) size — for composite_pass.hpp.
//
// Why: the picture's colour is computed here once per internal pixel; composition, tone mapping
// and the background come after, at the target's size.
// Guarantees: with ambient occlusion, the depths of the opaque parts come from its prepass and
// are tested GL_LEQUAL (the same vertex shader lays the same depths), without it they are laid
// here; transparent parts draw front faces only, blended without writing depth, so parts behind
// them stay visible; the selected part gets its highlight rim, cut surfaces their hatching (its
// period scales with the supersampling, so it keeps its size on the screen). Cost: one draw per
// part. Needs a current OpenGL 3.3 core context, also for the destructor.
#pragma once

#include <epoxy/gl.h>

#include "segmesh_render/detail/frame.hpp"
#include "segmesh_render/detail/framebuffers.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::render {

class ShadingPass {
 public:
  ShadingPass();  // links the program
  ~ShadingPass();
  ShadingPass(const ShadingPass&) = delete;
  ShadingPass& operator=(const ShadingPass&) = delete;

  // Draws `f` into targets.color_fbo from the mesh pass state (frame.hpp) with the frame's
  // viewport; `ao`: SceneTargets::blurred_ao holds this frame's ambient occlusion and the depth
  // buffer its prepass. `samples`: the supersampling factor per axis.
  void render(const Frame& f, const RenderOptions& o, int samples, bool ao,
              const SceneTargets& targets);

 private:
  GLuint shade_ = 0;  // program
};

}  // namespace segmesh::render
