#include "segmesh_render/detail/frame.hpp"

#include <algorithm>

#include "segmesh/vec3.hpp"
#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/mat4.hpp"

namespace segmesh::render {

Frame prepare_frame(const Scene& scene, GpuMeshCache& meshes, const Camera& camera,
                    const RenderOptions& o, int w, int h, bool colors_needed) {
  Frame f;
  f.width = w;
  f.height = h;
  Bounds visible;
  std::vector<DrawItem> items;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    const Part& part = scene.parts[i];
    const GpuMesh& g = meshes[i];
    const float opacity = i < o.opacity.size() ? std::clamp(o.opacity[i], 0.0f, 1.0f) : 1.0f;
    if (!part.visible || opacity <= 0 || !g.vao) continue;
    if (colors_needed && o.color == ColorMode::quality) meshes.ensure_quality_colors(i, part.mesh);
    DrawItem d;
    d.index = i;
    d.part = &part;
    d.mesh = &g;
    d.opacity = opacity;
    d.model = part.transform;
    items.push_back(d);
    visible.merge(transformed_bounds(g.bounds, part.transform));
  }
  const double aspect = double(w) / double(h);
  const ClipRange range = clip_range(camera, visible);
  f.view = view_matrix(camera);
  f.projection = projection_matrix(camera, aspect, range.near, range.far);
  f.inverse_projection = inverse(f.projection);
  const CameraFrame cf = camera_frame(camera);
  for (DrawItem& d : items) {
    d.model_view = f.view * d.model;
    d.normal_view = mul3(upper3(f.view), normal_matrix(d.model));
    const Bounds b = transformed_bounds(d.mesh->bounds, d.model);
    d.depth = dot(b.center() - cf.eye, cf.forward);
    (d.opacity < 1 ? f.transparent : f.opaque).push_back(d);
  }
  // Back to front.
  std::sort(f.transparent.begin(), f.transparent.end(),
            [](const DrawItem& a, const DrawItem& b) { return a.depth > b.depth; });
  if (o.clip) {
    const Vec3d n = normalized(o.clip->normal);
    if (norm(n) > 0) {
      f.clipped = true;
      f.clip = {float(n.x), float(n.y), float(n.z), float(-dot(n, o.clip->point))};
    }
  }
  f.ao = ao_parameters(o, visible.diagonal());
  return f;
}

void begin_mesh_pass(const Frame& f) {
  if (f.clipped) {
    glEnable(GL_CLIP_DISTANCE0);
  } else {
    glDisable(GL_CLIP_DISTANCE0);
  }
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDisable(GL_SCISSOR_TEST);
}

void set_mesh_uniforms(GLuint program, const Frame& f, const DrawItem& d) {
  set_uniform(program, "u_model", d.model);
  set_uniform(program, "u_model_view", d.model_view);
  set_uniform(program, "u_normal_view", d.normal_view);
  set_uniform(program, "u_projection", f.projection);
  set_uniform(program, "u_clip", f.clip[0], f.clip[1], f.clip[2], f.clip[3]);
}

void draw_mesh(const DrawItem& d) {
  glBindVertexArray(d.mesh->vao);
  glDrawElements(GL_TRIANGLES, d.mesh->index_count, GL_UNSIGNED_INT, nullptr);
}

}  // namespace segmesh::render
