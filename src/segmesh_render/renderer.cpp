// Renderer: a frame from its parts (detail/): the GPU meshes (gpu_mesh), the frame's parts and
// matrices (frame), ambient occlusion (ambient_occlusion), shading (shading_pass), composition
// into the caller's target (composite_pass) and part ids (picking), each pass with its own
// programs, on the buffers of detail/framebuffers.hpp.
#include "segmesh_render/renderer.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "segmesh/error.hpp"
#include "segmesh_render/detail/ambient_occlusion.hpp"
#include "segmesh_render/detail/composite_pass.hpp"
#include "segmesh_render/detail/frame.hpp"
#include "segmesh_render/detail/framebuffers.hpp"
#include "segmesh_render/detail/gl_program.hpp"
#include "segmesh_render/detail/gl_state.hpp"
#include "segmesh_render/detail/gpu_mesh.hpp"
#include "segmesh_render/detail/picking.hpp"
#include "segmesh_render/detail/shading_pass.hpp"

namespace segmesh::render {

std::string_view color_mode_name(ColorMode mode) {
  return mode == ColorMode::quality ? "quality" : "material";
}

std::optional<ColorMode> parse_color_mode(std::string_view name) {
  if (name == "material") return ColorMode::material;
  if (name == "quality") return ColorMode::quality;
  return std::nullopt;
}

AoParameters ao_parameters(const RenderOptions& o, double visible_diagonal_mm) {
  AoParameters a;
  a.radius_mm = o.ao_radius_mm > 0 ? o.ao_radius_mm : std::clamp(0.06 * visible_diagonal_mm, 2.0, 10.0);
  a.bias_mm = o.ao_bias_mm > 0 ? o.ao_bias_mm : 0.03 * a.radius_mm;
  return a;
}

namespace {

// Throws unless the current context is OpenGL 3.3 or later (before any program is linked).
int require_gl33() {
  if (epoxy_gl_version() < 33) {
    throw std::runtime_error("renderer: needs OpenGL 3.3 core; the current context has " +
                             std::to_string(epoxy_gl_version() / 10) + "." +
                             std::to_string(epoxy_gl_version() % 10));
  }
  return epoxy_gl_version();
}

// The largest side of a texture and of a renderbuffer this driver makes.
GLint max_target_size() {
  GLint tex = 0, rb = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &tex);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb);
  return std::max(1, std::min(tex, rb));
}

}  // namespace

struct Renderer::Impl {
  int gl_version = require_gl33();  // first: throws before any OpenGL object is made
  ShadingPass shading;
  AmbientOcclusion ambient_occlusion;
  Picking picking;
  CompositePass composite;
  FullscreenTriangle triangle;
  GLint max_size = max_target_size();
  GpuMeshCache meshes;
  FrameStats stats;
  SceneTargets targets;  // the frame's buffers, sized to the supersampled viewport
  ImageTarget image;     // render_image's target

  void check_size(int w, int h) const {
    if (w <= 0 || h <= 0) throw Error("the image size must be positive");
    if (w > max_size || h > max_size) {
      throw Error("an image of " + std::to_string(w) + " x " + std::to_string(h) +
                  " pixels is larger than this OpenGL driver renders (at most " +
                  std::to_string(max_size) + " per side)");
    }
  }

  void sync(const Scene& scene) { stats.meshes_uploaded = meshes.sync(scene); }

  // The frame's parts, matrices and clip plane for an internal size w x h; counts them.
  Frame prepare(const Scene& scene, const Camera& camera, const RenderOptions& o, int w, int h,
                bool colors_needed) {
    sync(scene);
    Frame f = prepare_frame(scene, meshes, camera, o, w, h, colors_needed);
    stats.parts_drawn = int(f.opaque.size() + f.transparent.size());
    stats.triangles_drawn = 0;
    for (const auto* items : {&f.opaque, &f.transparent}) {
      for (const DrawItem& d : *items) stats.triangles_drawn += d.mesh->index_count / 3;
    }
    return f;
  }

  void draw(const Scene& scene, const Camera& camera, const RenderOptions& o, const Viewport& vp) {
    if (vp.width <= 0 || vp.height <= 0) return;
    const SavedTarget saved = save_target();
    int samples = std::clamp(o.supersample, 1, 4);
    while (samples > 1 && (vp.width * samples > max_size || vp.height * samples > max_size)) {
      --samples;
    }
    Frame f = prepare(scene, camera, o, vp.width * samples, vp.height * samples, true);
    f.samples = samples;

    // Linear, premultiplied colour at the internal size; ambient occlusion at the viewport's.
    targets.ensure(f.width, f.height, samples);
    glViewport(0, 0, f.width, f.height);
    begin_mesh_pass(f);
    const bool ao = o.ambient_occlusion && o.ao_strength > 0 && !f.opaque.empty();
    if (ao) {
      ambient_occlusion.render(f, targets, triangle);
      begin_mesh_pass(f);
    }
    shading.render(f, o, samples, ao, targets);

    composite.render(targets.color, samples, o, GLuint(saved.draw), vp, triangle);
    restore_target(saved);
  }
};

namespace {
void flip_rows(RgbaImage& image) {
  // OpenGL's rows run bottom to top.
  const size_t row = size_t(image.width) * 4;
  for (int y = 0; y < image.height / 2; ++y) {
    std::swap_ranges(image.rgba.begin() + y * row, image.rgba.begin() + (y + 1) * row,
                     image.rgba.begin() + (image.height - 1 - y) * row);
  }
}
}  // namespace

RgbaImage read_framebuffer(const Viewport& viewport) {
  RgbaImage image;
  if (viewport.width <= 0 || viewport.height <= 0) return image;
  image.width = viewport.width;
  image.height = viewport.height;
  image.rgba.resize(size_t(image.width) * size_t(image.height) * 4);
  GLint alignment = 4;
  glGetIntegerv(GL_PACK_ALIGNMENT, &alignment);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(viewport.x, viewport.y, viewport.width, viewport.height, GL_RGBA, GL_UNSIGNED_BYTE,
               image.rgba.data());
  glPixelStorei(GL_PACK_ALIGNMENT, alignment);
  flip_rows(image);
  return image;
}

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

void Renderer::sync(const Scene& scene) {
  impl_->sync(scene);
}

void Renderer::invalidate(size_t index) {
  impl_->meshes.invalidate(index);
}

void Renderer::draw(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    const Viewport& viewport) {
  impl_->draw(scene, camera, options, viewport);
}

RgbaImage Renderer::render_image(const Scene& scene, const Camera& camera,
                                 const RenderOptions& options, int width, int height) {
  impl_->check_size(width, height);
  const SavedTarget saved = save_target();
  impl_->image.ensure(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->image.fbo);
  impl_->draw(scene, camera, options, Viewport{0, 0, width, height});
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->image.fbo);
  RgbaImage image = read_framebuffer(Viewport{0, 0, width, height});
  restore_target(saved);
  return image;
}

std::vector<int32_t> Renderer::render_ids(const Scene& scene, const Camera& camera,
                                          const RenderOptions& options, int width, int height) {
  impl_->check_size(width, height);
  const SavedTarget saved = save_target();
  impl_->picking.render(impl_->prepare(scene, camera, options, width, height, false), nullptr);
  std::vector<int32_t> ids = impl_->picking.read_all();
  restore_target(saved);
  return ids;
}

std::optional<size_t> Renderer::pick(const Scene& scene, const Camera& camera,
                                     const RenderOptions& options, int width, int height, int x,
                                     int y) {
  if (x < 0 || y < 0 || x >= width || y >= height) return std::nullopt;
  impl_->check_size(width, height);
  const SavedTarget saved = save_target();
  const int gl_y = height - 1 - y;
  const std::array<int, 4> scissor{x, gl_y, 1, 1};
  impl_->picking.render(impl_->prepare(scene, camera, options, width, height, false), &scissor);
  const std::optional<size_t> part = impl_->picking.read_pixel(x, gl_y);
  restore_target(saved);
  return part;
}

const FrameStats& Renderer::last_frame() const {
  return impl_->stats;
}

}  // namespace segmesh::render
