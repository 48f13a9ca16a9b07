// Screen-space ambient occlusion: the depth and normal prepass of a frame's opaque parts, the
// occlusion from it, and a depth-aware blur, leaving one channel (1: open, 0: fully occluded) in
// SceneTargets::blurred_ao for the shading pass.
//
// Why: creases (a plate on bone, a fracture gap) read clearly only with some ambient occlusion,
// and a screen-space estimate costs three passes whatever the meshes' size.
// Guarantees: the occlusion of a pixel takes 16 samples in a normal-oriented hemisphere of the
// frame's radius, rotated per pixel by a 4x4 tile of angles and range-checked so distant surfaces
// do not occlude; the blur averages the 4x4 tile and leaves out samples across a depth
// discontinuity. The kernel and the tile come from a fixed-seed generator: every Renderer draws
// the same picture. The prepass lays the depths the shading pass then reuses (GL_LEQUAL).
// Cost: a depth and normal pass over the opaque triangles and two full-screen passes at the
// internal size. Needs a current OpenGL 3.3 core context, also for the destructor.
#pragma once

#include <epoxy/gl.h>

#include <array>

#include "segmesh_render/detail/frame.hpp"
#include "segmesh_render/detail/framebuffers.hpp"
#include "segmesh_render/detail/gl_program.hpp"

namespace segmesh::render {

class AmbientOcclusion {
 public:
  AmbientOcclusion();  // links the three programs, makes the kernel and the noise tile
  ~AmbientOcclusion();
  AmbientOcclusion(const AmbientOcclusion&) = delete;
  AmbientOcclusion& operator=(const AmbientOcclusion&) = delete;

  // Runs the three passes of `f` into `targets` (sized to the frame), starting from the mesh
  // pass state (frame.hpp) with the frame's viewport. Leaves depth testing and clip distance 0
  // off.
  void render(const Frame& f, const SceneTargets& targets, const FullscreenTriangle& triangle);

 private:
  GLuint normal_ = 0, ssao_ = 0, blur_ = 0;  // programs
  std::array<float, 48> kernel_{};           // 16 view-space offsets, unit radius
  GLuint noise_ = 0;                         // 4x4 RG16F texture of rotations
};

}  // namespace segmesh::render
