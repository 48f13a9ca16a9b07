// Screen-space ambient occlusion: the depth and normal prepass of a frame's opaque parts, the
// occlusion from it, and a depth-aware blur, leaving one channel (1: open, 0: fully occluded) in
// SceneTargets::blurred_ao, at the output size, for the shading pass.
//
// Why: creases (a fragment resting on bone, a screw entering it, a plate on bone, a fracture gap)
// read clearly only with some ambient occlusion, and a screen-space estimate costs three passes
// whatever the meshes' size.
// Method: ambient obscurance in the manner of McGuire et al., "The Alchemy Screen-Space Ambient
// Obscurance Algorithm" (HPG 2011) and "Scalable Ambient Obscurance" (HPG 2012): 24 points of the
// visible surfaces on a spiral over a screen disc that is the frame's world radius (mm) at the
// pixel's depth, each occluding by how far it rises above the pixel's tangent plane, less the
// frame's bias, fading out at the radius (shaders.cpp, ssao_fragment).
// Guarantees: radius and bias are world millimetres (renderer.hpp, ao_parameters), so the same
// view darkens the same creases at any picture size and supersampling; flat and convex open
// surfaces do not occlude themselves; surfaces farther than the radius and the background occlude
// nothing. The spiral's starting angle comes from a 4x4 tile and the blur averages that tile,
// leaving out samples across a depth discontinuity. The tile comes from a fixed-seed generator:
// every Renderer draws the same picture. The prepass lays the depths the shading pass then reuses
// (GL_LEQUAL).
// Cost: a depth and normal pass over the opaque triangles at the internal size and two
// full-screen passes at the output size (24 and 16 depth reads a pixel). Needs a current OpenGL
// 3.3 core context, also for the destructor.
#pragma once

#include <epoxy/gl.h>

#include "segmesh_render/detail/frame.hpp"
#include "segmesh_render/detail/framebuffers.hpp"
#include "segmesh_render/detail/gl_program.hpp"

namespace segmesh::render {

class AmbientOcclusion {
 public:
  AmbientOcclusion();  // links the three programs, makes the noise tile
  ~AmbientOcclusion();
  AmbientOcclusion(const AmbientOcclusion&) = delete;
  AmbientOcclusion& operator=(const AmbientOcclusion&) = delete;

  // Runs the three passes of `f` into `targets` (sized to the frame), starting from the mesh
  // pass state (frame.hpp) with the frame's viewport. Leaves depth testing and clip distance 0
  // off and the frame's viewport set.
  void render(const Frame& f, const SceneTargets& targets, const FullscreenTriangle& triangle);

 private:
  GLuint normal_ = 0, ssao_ = 0, blur_ = 0;  // programs
  GLuint noise_ = 0;                         // 4x4 RG16F texture of rotations
};

}  // namespace segmesh::render
