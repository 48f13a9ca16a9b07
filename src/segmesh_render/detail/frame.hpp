// Frame: what one frame draws — the visible parts with their matrices, split into opaque and
// transparent (back to front), the projection, the clipping plane and the ambient occlusion
// radius and bias — and how a mesh pass draws those parts.
//
// Why: every pass of a frame (depth and normal prepass, shading, part ids) draws the same parts
// with the same matrices; preparing them once keeps the passes' depths identical (the shading
// pass reuses the prepass's depth buffer) and lets picking see exactly what draw() shows.
// Guarantees: matrices are composed in double precision and handed to the shaders as floats;
// hidden parts, parts of opacity 0 and empty meshes are left out; the near and far planes fit
// the drawn parts. Cost: per part a few 4x4 products; prepare_frame may upload quality colours
// (gpu_mesh.hpp) the first time a frame needs them. Needs a current OpenGL 3.3 core context.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstddef>
#include <vector>

#include "segmesh/scene.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/detail/gpu_mesh.hpp"
#include "segmesh_render/detail/mat3.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::render {

// One part as a frame draws it.
struct DrawItem {
  size_t index = 0;  // in Scene::parts
  const Part* part = nullptr;
  const GpuMesh* mesh = nullptr;
  float opacity = 1;
  Mat4 model{}, model_view{};
  Mat3 normal_view{};
  double depth = 0;  // of the transformed bounds' centre along the view direction
};

struct Frame {
  int width = 0, height = 0;  // internal (supersampled) pixels
  int samples = 1;            // supersampling factor per axis: internal pixels per output pixel
  Mat4 view{}, projection{}, inverse_projection{};
  std::array<float, 4> clip{0, 0, 0, 1};  // the plane as the shaders take it (kept where >= 0)
  bool clipped = false;
  AoParameters ao;                            // world mm (renderer.hpp)
  std::vector<DrawItem> opaque, transparent;  // transparent: back to front
};

// The frame of `scene` seen by `camera` at w x h internal pixels. `meshes` must have been synced
// with `scene`; with `colors_needed` and ColorMode::quality, parts without colours get quality
// colours uploaded first.
Frame prepare_frame(const Scene& scene, GpuMeshCache& meshes, const Camera& camera,
                    const RenderOptions& options, int w, int h, bool colors_needed);

// The OpenGL state every mesh pass starts from: depth test and writes on, no blending, no culling,
// no scissor test, clip distance 0 on when the frame is clipped.
void begin_mesh_pass(const Frame& f);

// The matrices and clip plane of mesh_vertex for item `d`, into `program` (in use).
void set_mesh_uniforms(GLuint program, const Frame& f, const DrawItem& d);

// Draws `d`'s triangles with the program in use.
void draw_mesh(const DrawItem& d);

}  // namespace segmesh::render
