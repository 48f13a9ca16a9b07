#include "segmesh_render/renderer.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "segmesh/error.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_render/detail/shaders.hpp"

namespace segmesh::render {

std::string_view color_mode_name(ColorMode mode) {
  return mode == ColorMode::quality ? "quality" : "material";
}

std::optional<ColorMode> parse_color_mode(std::string_view name) {
  if (name == "material") return ColorMode::material;
  if (name == "quality") return ColorMode::quality;
  return std::nullopt;
}

namespace {

// ---- small helpers -------------------------------------------------------------------------

using Mat3 = std::array<double, 9>;  // column-major

std::array<float, 16> to_float(const Mat4& m) {
  std::array<float, 16> f{};
  for (int i = 0; i < 16; ++i) f[i] = static_cast<float>(m[i]);
  return f;
}

Mat3 upper3(const Mat4& m) { return {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]}; }

Mat3 mul3(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row)
      for (int k = 0; k < 3; ++k) r[3 * c + row] += a[3 * k + row] * b[3 * c + k];
  return r;
}

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

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

uint64_t fnv(uint64_t h, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
  return h;
}

template <class T>
uint64_t sample_hash(uint64_t h, const std::vector<T>& v, size_t samples) {
  const size_t n = v.size();
  h = fnv(h, &n, sizeof n);
  if (n == 0) return h;
  for (size_t k = 0; k < samples; ++k) {
    const size_t i = samples == 1 ? 0 : k * (n - 1) / (samples - 1);
    h = fnv(h, &v[i], sizeof(T));
  }
  return h;
}

// Counts and a hash of sampled entries: cheap, and changes whenever the pipeline replaces or
// smooths a mesh (every vertex moves).
uint64_t mesh_fingerprint(const TriMesh& m) {
  uint64_t h = 0xCBF29CE484222325ull;
  h = sample_hash(h, m.positions, 97);
  h = sample_hash(h, m.indices, 97);
  h = sample_hash(h, m.normals, 31);
  h = sample_hash(h, m.colors, 31);
  return h;
}

std::vector<Vec3f> vertex_normals(const TriMesh& m) {
  std::vector<Vec3d> sum(m.positions.size());
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
    const Vec3d pa = to_double(m.positions[a]), pb = to_double(m.positions[b]),
                pc = to_double(m.positions[c]);
    const Vec3d n = cross(pb - pa, pc - pa);  // area-weighted
    sum[a] = sum[a] + n;
    sum[b] = sum[b] + n;
    sum[c] = sum[c] + n;
  }
  std::vector<Vec3f> out(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) out[i] = to_float(normalized(sum[i]));
  return out;
}

GLuint compile(GLenum type, const char* source, const char* name) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(std::string("renderer: shader ") + name + " does not compile: " + log);
  }
  return shader;
}

GLuint link(const char* vertex, const char* fragment, const char* name) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex, name);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glBindAttribLocation(program, 0, "a_position");
  glBindAttribLocation(program, 1, "a_normal");
  glBindAttribLocation(program, 2, "a_color");
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    throw std::runtime_error(std::string("renderer: program ") + name + " does not link: " + log);
  }
  return program;
}

// Uniform setters by name (the programs are small; lookups cost nothing next to a frame).
GLint loc(GLuint p, const char* name) { return glGetUniformLocation(p, name); }
void set(GLuint p, const char* n, int v) { glUniform1i(loc(p, n), v); }
void set(GLuint p, const char* n, float v) { glUniform1f(loc(p, n), v); }
void set(GLuint p, const char* n, float x, float y) { glUniform2f(loc(p, n), x, y); }
void set(GLuint p, const char* n, float x, float y, float z) { glUniform3f(loc(p, n), x, y, z); }
void set(GLuint p, const char* n, float x, float y, float z, float w) {
  glUniform4f(loc(p, n), x, y, z, w);
}
void set(GLuint p, const char* n, const Mat4& m) {
  const auto f = to_float(m);
  glUniformMatrix4fv(loc(p, n), 1, GL_FALSE, f.data());
}
void set(GLuint p, const char* n, const Mat3& m) {
  std::array<float, 9> f{};
  for (int i = 0; i < 9; ++i) f[i] = static_cast<float>(m[i]);
  glUniformMatrix3fv(loc(p, n), 1, GL_FALSE, f.data());
}

GLuint make_texture(GLenum internal, GLenum format, GLenum type, int w, int h) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

GLuint make_framebuffer(std::initializer_list<GLuint> colors, GLuint depth_texture,
                        GLuint depth_renderbuffer = 0) {
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  GLenum buffers[4];
  GLsizei n = 0;
  for (GLuint c : colors) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + n, GL_TEXTURE_2D, c, 0);
    buffers[n] = GL_COLOR_ATTACHMENT0 + n;
    ++n;
  }
  glDrawBuffers(n, buffers);
  if (depth_texture) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth_texture, 0);
  }
  if (depth_renderbuffer) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              depth_renderbuffer);
  }
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("renderer: incomplete framebuffer");
  }
  return fbo;
}

// ---- GPU resources -------------------------------------------------------------------------

struct GpuMesh {
  GLuint vao = 0, positions = 0, normals = 0, colors = 0, indices = 0;
  GLsizei index_count = 0;
  uint64_t fingerprint = 0;
  bool stale = false;
  bool has_colors = false;      // the colour buffer holds the mesh's own colours
  bool quality_colors = false;  // the colour buffer holds colours computed from the radii ratio
  Bounds bounds;                // local (before the part's transform)

  void release() {
    if (vao) glDeleteVertexArrays(1, &vao);
    GLuint buffers[] = {positions, normals, colors, indices};
    for (GLuint b : buffers)
      if (b) glDeleteBuffers(1, &b);
    *this = GpuMesh{};
  }
};

void upload_colors(GpuMesh& g, const std::vector<Rgba8>& colors) {
  glBindVertexArray(g.vao);
  if (!g.colors) glGenBuffers(1, &g.colors);
  glBindBuffer(GL_ARRAY_BUFFER, g.colors);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(colors.size() * sizeof(Rgba8)), colors.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, 0, nullptr);
  glBindVertexArray(0);
}

void upload(GpuMesh& g, const TriMesh& mesh) {
  g.release();
  g.fingerprint = mesh_fingerprint(mesh);
  g.bounds = mesh_bounds(mesh);
  if (mesh.empty() || mesh.positions.empty()) return;
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  glGenBuffers(1, &g.positions);
  glBindBuffer(GL_ARRAY_BUFFER, g.positions);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.positions.size() * sizeof(Vec3f)),
               mesh.positions.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3f), nullptr);
  glGenBuffers(1, &g.normals);
  glBindBuffer(GL_ARRAY_BUFFER, g.normals);
  const std::vector<Vec3f> computed =
      mesh.normals.size() == mesh.positions.size() ? std::vector<Vec3f>{} : vertex_normals(mesh);
  const std::vector<Vec3f>& normals = computed.empty() ? mesh.normals : computed;
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(normals.size() * sizeof(Vec3f)), normals.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vec3f), nullptr);
  glGenBuffers(1, &g.indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  g.index_count = GLsizei(mesh.indices.size());
  glBindVertexArray(0);
  if (mesh.colors.size() == mesh.positions.size()) {
    upload_colors(g, mesh.colors);
    g.has_colors = true;
  }
}

// One part as a frame draws it.
struct DrawItem {
  size_t index = 0;
  const Part* part = nullptr;
  const GpuMesh* mesh = nullptr;
  float opacity = 1;
  Mat4 model{}, model_view{};
  Mat3 normal_view{};
  double depth = 0;  // of the transformed bounds' centre along the view direction
};

struct Frame {
  int width = 0, height = 0;  // internal (supersampled) pixels
  Mat4 view{}, projection{}, inverse_projection{};
  std::array<float, 4> clip{0, 0, 0, 1};
  bool clipped = false;
  double ao_radius = 1;
  std::vector<DrawItem> opaque, transparent;
};

}  // namespace

struct Renderer::Impl {
  GLuint shade = 0, normal = 0, id = 0, ssao = 0, blur = 0, composite = 0;
  GLuint empty_vao = 0;  // full-screen passes draw without attributes
  GLuint noise = 0;
  std::array<float, 48> kernel{};
  std::vector<GpuMesh> meshes;
  FrameStats stats;
  GLint max_size = 4096;

  // Internal buffers, sized to the supersampled viewport.
  int width = 0, height = 0;
  GLuint depth_tex = 0, normal_tex = 0, color_tex = 0, ao_tex = 0, blur_tex = 0;
  GLuint prepass_fbo = 0, color_fbo = 0, ao_fbo = 0, blur_fbo = 0;
  // Part ids, at the viewport's own size.
  int id_width = 0, id_height = 0;
  GLuint id_tex = 0, id_depth = 0, id_fbo = 0;
  // render_image's target.
  int out_width = 0, out_height = 0;
  GLuint out_color = 0, out_fbo = 0;

  Impl() {
    if (epoxy_gl_version() < 33) {
      throw std::runtime_error("renderer: needs OpenGL 3.3 core; the current context has " +
                               std::to_string(epoxy_gl_version() / 10) + "." +
                               std::to_string(epoxy_gl_version() % 10));
    }
    shade = link(shaders::mesh_vertex, shaders::shade_fragment, "shade");
    normal = link(shaders::mesh_vertex, shaders::normal_fragment, "normal");
    id = link(shaders::mesh_vertex, shaders::id_fragment, "id");
    ssao = link(shaders::fullscreen_vertex, shaders::ssao_fragment, "ssao");
    blur = link(shaders::fullscreen_vertex, shaders::blur_fragment, "blur");
    composite = link(shaders::fullscreen_vertex, shaders::composite_fragment, "composite");
    glGenVertexArrays(1, &empty_vao);
    GLint tex = 0, rb = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &tex);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &rb);
    max_size = std::max(1, std::min(tex, rb));

    Random random;
    for (int i = 0; i < 16; ++i) {
      // A point in the upper unit hemisphere, denser towards the centre.
      Vec3d s{random.next() * 2 - 1, random.next() * 2 - 1, random.next() * 0.85 + 0.15};
      s = normalized(s);
      double scale = double(i) / 16;
      scale = 0.1 + 0.9 * scale * scale;
      s = (scale * (0.5 + 0.5 * random.next())) * s;
      kernel[3 * i] = float(s.x), kernel[3 * i + 1] = float(s.y), kernel[3 * i + 2] = float(s.z);
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
    noise = make_texture(GL_RG16F, GL_RG, GL_FLOAT, 4, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 4, 4, GL_RG, GL_FLOAT, rotations.data());
    glBindTexture(GL_TEXTURE_2D, 0);
  }

  ~Impl() {
    for (GpuMesh& m : meshes) m.release();
    release_internal();
    release_ids();
    release_out();
    for (GLuint p : {shade, normal, id, ssao, blur, composite}) glDeleteProgram(p);
    glDeleteVertexArrays(1, &empty_vao);
    glDeleteTextures(1, &noise);
  }

  void release_internal() {
    GLuint fbos[] = {prepass_fbo, color_fbo, ao_fbo, blur_fbo};
    GLuint texs[] = {depth_tex, normal_tex, color_tex, ao_tex, blur_tex};
    for (GLuint f : fbos)
      if (f) glDeleteFramebuffers(1, &f);
    for (GLuint t : texs)
      if (t) glDeleteTextures(1, &t);
    prepass_fbo = color_fbo = ao_fbo = blur_fbo = 0;
    depth_tex = normal_tex = color_tex = ao_tex = blur_tex = 0;
    width = height = 0;
  }

  void release_ids() {
    if (id_fbo) glDeleteFramebuffers(1, &id_fbo);
    if (id_tex) glDeleteTextures(1, &id_tex);
    if (id_depth) glDeleteRenderbuffers(1, &id_depth);
    id_fbo = id_tex = id_depth = 0;
    id_width = id_height = 0;
  }

  void release_out() {
    if (out_fbo) glDeleteFramebuffers(1, &out_fbo);
    if (out_color) glDeleteRenderbuffers(1, &out_color);
    out_fbo = out_color = 0;
    out_width = out_height = 0;
  }

  void ensure_internal(int w, int h) {
    if (w == width && h == height) return;
    release_internal();
    depth_tex = make_texture(GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, w, h);
    normal_tex = make_texture(GL_RGBA16F, GL_RGBA, GL_FLOAT, w, h);
    color_tex = make_texture(GL_RGBA16F, GL_RGBA, GL_FLOAT, w, h);
    ao_tex = make_texture(GL_R8, GL_RED, GL_UNSIGNED_BYTE, w, h);
    blur_tex = make_texture(GL_R8, GL_RED, GL_UNSIGNED_BYTE, w, h);
    glBindTexture(GL_TEXTURE_2D, 0);
    prepass_fbo = make_framebuffer({normal_tex}, depth_tex);
    color_fbo = make_framebuffer({color_tex}, depth_tex);
    ao_fbo = make_framebuffer({ao_tex}, 0);
    blur_fbo = make_framebuffer({blur_tex}, 0);
    width = w;
    height = h;
  }

  void ensure_ids(int w, int h) {
    if (w == id_width && h == id_height) return;
    release_ids();
    id_tex = make_texture(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, w, h);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenRenderbuffers(1, &id_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, id_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    id_fbo = make_framebuffer({id_tex}, 0, id_depth);
    id_width = w;
    id_height = h;
  }

  void ensure_out(int w, int h) {
    if (w == out_width && h == out_height) return;
    release_out();
    glGenRenderbuffers(1, &out_color);
    glBindRenderbuffer(GL_RENDERBUFFER, out_color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glGenFramebuffers(1, &out_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, out_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, out_color);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("renderer: incomplete output framebuffer");
    }
    out_width = w;
    out_height = h;
  }

  void check_size(int w, int h) const {
    if (w <= 0 || h <= 0) throw Error("the image size must be positive");
    if (w > max_size || h > max_size) {
      throw Error("an image of " + std::to_string(w) + " x " + std::to_string(h) +
                  " pixels is larger than this OpenGL driver renders (at most " +
                  std::to_string(max_size) + " per side)");
    }
  }

  void sync(const Scene& scene) {
    stats.meshes_uploaded = 0;
    for (size_t i = scene.parts.size(); i < meshes.size(); ++i) meshes[i].release();
    meshes.resize(scene.parts.size());
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      GpuMesh& g = meshes[i];
      const TriMesh& m = scene.parts[i].mesh;
      if (!g.stale && g.fingerprint == mesh_fingerprint(m) && (g.vao || m.empty())) continue;
      upload(g, m);
      ++stats.meshes_uploaded;
    }
  }

  // The frame's parts, matrices and clip plane for an internal size w x h.
  Frame prepare(const Scene& scene, const Camera& camera, const RenderOptions& o, int w, int h,
                bool colors_needed) {
    sync(scene);
    Frame f;
    f.width = w;
    f.height = h;
    Bounds visible;
    std::vector<DrawItem> items;
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      const Part& part = scene.parts[i];
      GpuMesh& g = meshes[i];
      const float opacity = i < o.opacity.size() ? std::clamp(o.opacity[i], 0.0f, 1.0f) : 1.0f;
      if (!part.visible || opacity <= 0 || !g.vao) continue;
      if (colors_needed && o.color == ColorMode::quality && !g.has_colors && !g.quality_colors) {
        upload_colors(g, quality_colors(vertex_quality(part.mesh)));
        g.quality_colors = true;
      }
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
    f.ao_radius = o.ao_radius_mm > 0 ? o.ao_radius_mm : 0.02 * std::max(visible.diagonal(), 1e-3);
    stats.parts_drawn = int(items.size());
    stats.triangles_drawn = 0;
    for (const DrawItem& d : items) stats.triangles_drawn += d.mesh->index_count / 3;
    return f;
  }

  void set_mesh_uniforms(GLuint program, const Frame& f, const DrawItem& d) {
    set(program, "u_model", d.model);
    set(program, "u_model_view", d.model_view);
    set(program, "u_normal_view", d.normal_view);
    set(program, "u_projection", f.projection);
    set(program, "u_clip", f.clip[0], f.clip[1], f.clip[2], f.clip[3]);
  }

  void draw_mesh(const DrawItem& d) {
    glBindVertexArray(d.mesh->vao);
    glDrawElements(GL_TRIANGLES, d.mesh->index_count, GL_UNSIGNED_INT, nullptr);
  }

  void begin_meshes(const Frame& f) {
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

  void fullscreen(GLuint program) {
    glUseProgram(program);
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }

  // Renders the frame into color_tex (linear, premultiplied) at the internal size.
  void render_color(const Frame& f, const RenderOptions& o, int samples) {
    ensure_internal(f.width, f.height);
    glViewport(0, 0, f.width, f.height);
    begin_meshes(f);
    const bool ao = o.ambient_occlusion && o.ao_strength > 0 && !f.opaque.empty();
    if (ao) {
      glBindFramebuffer(GL_FRAMEBUFFER, prepass_fbo);
      const float zero[4] = {0, 0, 1, 0};
      glClearBufferfv(GL_COLOR, 0, zero);
      glClear(GL_DEPTH_BUFFER_BIT);
      glDepthFunc(GL_LESS);
      glUseProgram(normal);
      for (const DrawItem& d : f.opaque) {
        set_mesh_uniforms(normal, f, d);
        draw_mesh(d);
      }
      glDisable(GL_DEPTH_TEST);
      glDisable(GL_CLIP_DISTANCE0);
      glBindFramebuffer(GL_FRAMEBUFFER, ao_fbo);
      glUseProgram(ssao);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, depth_tex);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, normal_tex);
      glActiveTexture(GL_TEXTURE2);
      glBindTexture(GL_TEXTURE_2D, noise);
      set(ssao, "u_depth", 0);
      set(ssao, "u_normal", 1);
      set(ssao, "u_noise", 2);
      set(ssao, "u_projection", f.projection);
      set(ssao, "u_inverse_projection", f.inverse_projection);
      glUniform3fv(loc(ssao, "u_kernel"), 16, kernel.data());
      set(ssao, "u_radius", float(f.ao_radius));
      set(ssao, "u_size", float(f.width), float(f.height));
      fullscreen(ssao);
      glBindFramebuffer(GL_FRAMEBUFFER, blur_fbo);
      glUseProgram(blur);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, ao_tex);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, depth_tex);
      set(blur, "u_ao", 0);
      set(blur, "u_depth", 1);
      set(blur, "u_inverse_projection", f.inverse_projection);
      set(blur, "u_radius", float(f.ao_radius));
      fullscreen(blur);
      begin_meshes(f);
    }

    glBindFramebuffer(GL_FRAMEBUFFER, color_fbo);
    const float clear[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, clear);
    if (ao) {
      glDepthFunc(GL_LEQUAL);  // the prepass laid the same depths (invariant gl_Position)
    } else {
      glClear(GL_DEPTH_BUFFER_BIT);
      glDepthFunc(GL_LESS);
    }
    glUseProgram(shade);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, ao ? blur_tex : 0);
    set(shade, "u_ao", 0);
    set(shade, "u_use_ao", ao ? 1 : 0);
    set(shade, "u_ao_strength", float(std::clamp(o.ao_strength, 0.0, 1.0)));
    set(shade, "u_clipped", f.clipped ? 1 : 0);
    set(shade, "u_hatch_period", float(8 * samples));
    const bool quality = o.color == ColorMode::quality;
    auto draw_items = [&](const std::vector<DrawItem>& items) {
      for (const DrawItem& d : items) {
        const Material& m = d.part->material;
        set_mesh_uniforms(shade, f, d);
        set(shade, "u_base_color", m.base_color.r, m.base_color.g, m.base_color.b);
        set(shade, "u_metallic", m.metallic);
        set(shade, "u_roughness", m.roughness);
        set(shade, "u_opacity", d.opacity);
        set(shade, "u_vertex_color", quality ? 1 : 0);
        set(shade, "u_highlight", int(d.index) == o.selected ? 1.0f : 0.0f);
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

  // The caller's framebuffers and viewport, saved on entry and restored on exit.
  struct Saved {
    GLint draw = 0, read = 0, viewport[4] = {0, 0, 0, 0};
  };
  static Saved save() {
    Saved s;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s.draw);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s.read);
    glGetIntegerv(GL_VIEWPORT, s.viewport);
    return s;
  }

  void restore(const Saved& s) {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(s.draw));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(s.read));
    const GLint* viewport = s.viewport;
    glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glDisable(GL_CLIP_DISTANCE0);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glUseProgram(0);
    glBindVertexArray(0);
    for (int unit = 2; unit >= 0; --unit) {
      glActiveTexture(GL_TEXTURE0 + unit);
      glBindTexture(GL_TEXTURE_2D, 0);
    }
  }

  void draw(const Scene& scene, const Camera& camera, const RenderOptions& o, const Viewport& vp) {
    if (vp.width <= 0 || vp.height <= 0) return;
    const Saved saved = save();
    int samples = std::clamp(o.supersample, 1, 4);
    while (samples > 1 && (vp.width * samples > max_size || vp.height * samples > max_size)) --samples;
    const Frame f = prepare(scene, camera, o, vp.width * samples, vp.height * samples, true);
    render_color(f, o, samples);

    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(saved.draw));
    glViewport(vp.x, vp.y, vp.width, vp.height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CLIP_DISTANCE0);
    glDisable(GL_SCISSOR_TEST);
    glUseProgram(composite);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, color_tex);
    set(composite, "u_color", 0);
    set(composite, "u_samples", samples);
    set(composite, "u_origin", float(vp.x), float(vp.y));
    set(composite, "u_size", float(vp.width), float(vp.height));
    const Rgb& top = o.background_top;
    const Rgb& bottom = o.background_bottom;
    set(composite, "u_background_top", srgb_to_linear(top.r), srgb_to_linear(top.g),
        srgb_to_linear(top.b));
    set(composite, "u_background_bottom", srgb_to_linear(bottom.r), srgb_to_linear(bottom.g),
        srgb_to_linear(bottom.b));
    set(composite, "u_exposure", float(o.exposure));
    fullscreen(composite);
    restore(saved);
  }

  // Renders part ids into id_fbo; only the rows and columns of `scissor` when given.
  void render_id_buffer(const Scene& scene, const Camera& camera, const RenderOptions& o, int w,
                        int h, const std::array<int, 4>* scissor) {
    const Frame f = prepare(scene, camera, o, w, h, false);
    ensure_ids(w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, id_fbo);
    glViewport(0, 0, w, h);
    begin_meshes(f);
    if (scissor) {
      glEnable(GL_SCISSOR_TEST);
      glScissor((*scissor)[0], (*scissor)[1], (*scissor)[2], (*scissor)[3]);
    }
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferuiv(GL_COLOR, 0, zero);
    glClear(GL_DEPTH_BUFFER_BIT);
    glDepthFunc(GL_LESS);
    glUseProgram(id);
    for (const auto* items : {&f.opaque, &f.transparent}) {
      for (const DrawItem& d : *items) {
        set_mesh_uniforms(id, f, d);
        glUniform1ui(loc(id, "u_id"), GLuint(d.index + 1));
        draw_mesh(d);
      }
    }
    glDisable(GL_SCISSOR_TEST);
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

void Renderer::sync(const Scene& scene) { impl_->sync(scene); }

void Renderer::invalidate(size_t index) {
  if (index < impl_->meshes.size()) impl_->meshes[index].stale = true;
}

void Renderer::draw(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    const Viewport& viewport) {
  impl_->draw(scene, camera, options, viewport);
}

RgbaImage Renderer::render_image(const Scene& scene, const Camera& camera,
                                 const RenderOptions& options, int width, int height) {
  impl_->check_size(width, height);
  const Impl::Saved saved = Impl::save();
  impl_->ensure_out(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->out_fbo);
  impl_->draw(scene, camera, options, Viewport{0, 0, width, height});
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->out_fbo);
  RgbaImage image = read_framebuffer(Viewport{0, 0, width, height});
  impl_->restore(saved);
  return image;
}

std::vector<int32_t> Renderer::render_ids(const Scene& scene, const Camera& camera,
                                          const RenderOptions& options, int width, int height) {
  impl_->check_size(width, height);
  const Impl::Saved saved = Impl::save();
  impl_->render_id_buffer(scene, camera, options, width, height, nullptr);
  std::vector<uint32_t> raw(size_t(width) * size_t(height));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->id_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, width, height, GL_RED_INTEGER, GL_UNSIGNED_INT, raw.data());
  std::vector<int32_t> ids(raw.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      ids[size_t(y) * width + x] = int32_t(raw[size_t(height - 1 - y) * width + x]) - 1;
    }
  }
  impl_->restore(saved);
  return ids;
}

std::optional<size_t> Renderer::pick(const Scene& scene, const Camera& camera,
                                     const RenderOptions& options, int width, int height, int x,
                                     int y) {
  if (x < 0 || y < 0 || x >= width || y >= height) return std::nullopt;
  impl_->check_size(width, height);
  const Impl::Saved saved = Impl::save();
  const int gl_y = height - 1 - y;
  const std::array<int, 4> scissor{x, gl_y, 1, 1};
  impl_->render_id_buffer(scene, camera, options, width, height, &scissor);
  GLuint value = 0;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->id_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(x, gl_y, 1, 1, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
  impl_->restore(saved);
  if (value == 0) return std::nullopt;
  return size_t(value - 1);
}

const FrameStats& Renderer::last_frame() const { return impl_->stats; }

}  // namespace segmesh::render
