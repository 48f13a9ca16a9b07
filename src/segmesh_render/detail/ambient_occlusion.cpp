#include "segmesh_render/detail/ambient_occlusion.hpp"

#include <cmath>
#include <cstdint>
#include <utility>

#include "segmesh/vec3.hpp"
#include "segmesh_render/detail/shaders.hpp"
#include "segmesh_render/mat4.hpp"

namespace segmesh::render {
namespace {

// A deterministic generator (xorshift64*) for the ambient occlusion kernel and noise, so every
// run draws the same picture.
struct Random {
  uint64_t state = 0x9E3779B97F4A7C15ull;
  double next() {  // [0, 1)
    state ^= state >> 12;
    state ^= state << 25;
    state ^= state >> 27;
    return double((state * 0x2545F4914F6CDD1Dull) >> 11) / double(1ull << 53);
  }
};

}  // namespace

AmbientOcclusion::AmbientOcclusion() {
  normal_ = link_program(shaders::mesh_vertex, shaders::normal_fragment, "normal");
  ssao_ = link_program(shaders::fullscreen_vertex, shaders::ssao_fragment, "ssao");
  blur_ = link_program(shaders::fullscreen_vertex, shaders::blur_fragment, "blur");

  Random random;
  for (int i = 0; i < 16; ++i) {
    // A point in the upper unit hemisphere, denser towards the centre.
    Vec3d s{random.next() * 2 - 1, random.next() * 2 - 1, random.next() * 0.85 + 0.15};
    s = normalized(s);
    double scale = double(i) / 16;
    scale = 0.1 + 0.9 * scale * scale;
    s = (scale * (0.5 + 0.5 * random.next())) * s;
    kernel_[3 * i] = float(s.x), kernel_[3 * i + 1] = float(s.y), kernel_[3 * i + 2] = float(s.z);
  }
  std::array<float, 32> rotations{};
  for (int i = 0; i < 16; ++i) {
    const double a = 2 * 3.14159265358979 * (i + random.next()) / 16;  // spread over the circle
    rotations[2 * i] = float(std::cos(a));
    rotations[2 * i + 1] = float(std::sin(a));
  }
  // Shuffle the 16 angles over the tile, deterministically.
  for (int i = 15; i > 0; --i) {
    const int j = int(random.next() * (i + 1));
    std::swap(rotations[2 * i], rotations[2 * j]);
    std::swap(rotations[2 * i + 1], rotations[2 * j + 1]);
  }
  noise_ = make_texture(GL_RG16F, GL_RG, GL_FLOAT, 4, 4);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, 4, GL_RG, GL_FLOAT, rotations.data());
  glBindTexture(GL_TEXTURE_2D, 0);
}

AmbientOcclusion::~AmbientOcclusion() {
  for (GLuint p : {normal_, ssao_, blur_}) glDeleteProgram(p);
  glDeleteTextures(1, &noise_);
}

void AmbientOcclusion::render(const Frame& f, const SceneTargets& targets,
                              const FullscreenTriangle& triangle) {
  // View-space normals and depth of the opaque parts.
  glBindFramebuffer(GL_FRAMEBUFFER, targets.prepass_fbo);
  const float zero[4] = {0, 0, 1, 0};
  glClearBufferfv(GL_COLOR, 0, zero);
  glClear(GL_DEPTH_BUFFER_BIT);
  glDepthFunc(GL_LESS);
  glUseProgram(normal_);
  for (const DrawItem& d : f.opaque) {
    set_mesh_uniforms(normal_, f, d);
    draw_mesh(d);
  }
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CLIP_DISTANCE0);

  // The occlusion.
  glBindFramebuffer(GL_FRAMEBUFFER, targets.ao_fbo);
  glUseProgram(ssao_);
  bind_samplers(ssao_,
                {{"u_depth", targets.depth}, {"u_normal", targets.normal}, {"u_noise", noise_}});
  set_uniform(ssao_, "u_projection", f.projection);
  set_uniform(ssao_, "u_inverse_projection", f.inverse_projection);
  glUniform3fv(uniform_location(ssao_, "u_kernel"), 16, kernel_.data());
  set_uniform(ssao_, "u_radius", float(f.ao_radius));
  set_uniform(ssao_, "u_size", float(f.width), float(f.height));
  triangle.draw(ssao_);

  // Its blur.
  glBindFramebuffer(GL_FRAMEBUFFER, targets.blur_fbo);
  glUseProgram(blur_);
  bind_samplers(blur_, {{"u_ao", targets.ao}, {"u_depth", targets.depth}});
  set_uniform(blur_, "u_inverse_projection", f.inverse_projection);
  set_uniform(blur_, "u_radius", float(f.ao_radius));
  triangle.draw(blur_);
}

}  // namespace segmesh::render
