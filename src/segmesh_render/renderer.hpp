// Renderer: draws a Scene with OpenGL 3.3 core — the planning viewer's picture and the pictures
// `segmesh render` and `segmesh study` write.
//
// Plain data in: every call takes the Scene (parts with mesh, material, transform, visibility),
// a Camera and RenderOptions; the renderer keeps nothing of them but the GPU copies of the meshes
// (uploaded on first use and again when a part's mesh changes) and its own framebuffers. It holds
// no global state and needs a current OpenGL 3.3 core context on the calling thread for every
// call, its constructor and destructor included: a window's (the viewer makes its GLFW context
// current) or a HeadlessContext (headless_context.hpp).
//
// What a frame is:
//   1. (ambient occlusion on) a depth and normal pass of the opaque parts, screen-space ambient
//      occlusion from it at the output resolution (24 samples on a spiral over a disc of the
//      world radius, each occluding by how far it rises above the pixel's tangent plane, fading
//      out at the radius; rotated per pixel by a 4x4 tile) and a depth-aware 4x4 blur;
//   2. the opaque parts, shaded physically (metallic-roughness: GGX distribution, height-
//      correlated Smith visibility, Schlick Fresnel) by two directional lights and a sky
//      (hemisphere) light; metals reflect an analytic sky (bright above, dark ground below,
//      blurred by roughness) through Karis' analytic environment BRDF, so a metallic part reads
//      as metal without an environment map. Ambient occlusion (squared) darkens the sky light
//      fully and the direct lights by three quarters, so creases (a plate on bone, a fracture
//      gap) read clearly while open surfaces keep their brightness;
//   3. the transparent parts (opacity < 1), back to front, front faces only;
//   4. composition into the target: tone mapping (ACES fit), the background gradient, averaging
//      of the supersamples and sRGB encoding.
// Lights are fixed to the camera (the key light above left and in front, a weaker fill light
// right and below, the sky above the screen), so every view is lit alike.
//
// The clipping plane cuts every part (gl_ClipDistance) and the cut is shown: the inside of a cut
// closed mesh (its back faces) is drawn flat in a darkened part colour with diagonal hatching,
// so a screw inside a cut bone stands out, shaded, against the bone's hatched section.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "segmesh/scene.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/png.hpp"

namespace segmesh::render {

enum class ColorMode {
  material,  // each part's Material (bone white, implant metallic red, ...)
  quality,   // the mesh's vertex colours: radii ratio, blue 0 to green 1 (quality.hpp); computed
             // from the mesh when it has none
};
std::string_view color_mode_name(ColorMode mode);
std::optional<ColorMode> parse_color_mode(std::string_view name);  // "material", "quality"

// A plane that keeps the half-space its normal points into: points p with
// dot(p - point, normal) >= 0 are drawn. World mm; the parts' transforms apply before the cut.
struct ClipPlane {
  Vec3d point{0, 0, 0};
  Vec3d normal{0, 0, 1};  // need not be unit length; must not be zero
};

struct RenderOptions {
  ColorMode color = ColorMode::material;
  bool ambient_occlusion = true;
  double ao_radius_mm = 0;    // how far occluders count, world mm; 0: ao_parameters' default
  double ao_bias_mm = 0;      // height above the tangent plane an occluder must exceed; 0: default
  double ao_strength = 1;     // 0 (none) .. 1 (full)
  std::optional<ClipPlane> clip;
  std::vector<float> opacity;  // per part, by index in Scene::parts; missing entries are 1
  int selected = -1;           // a part index to draw with a highlight rim; -1: none
  int supersample = 1;         // 1..4: render supersample^2 times the pixels and average them
  double exposure = 1;         // multiplies the light before tone mapping
  Rgb background_top{0.31f, 0.34f, 0.39f};     // sRGB
  Rgb background_bottom{0.09f, 0.10f, 0.12f};  // sRGB
};

// The ambient occlusion a frame uses, in world millimetres, whatever the picture's size or
// supersampling (`segmesh render` and the viewer draw the same occlusion for the same view):
// the radius is options.ao_radius_mm when positive, else 6 % of the visible parts' bounding
// diagonal clamped to 2..10 mm (a screw head, a fragment's rim, the width of a crease); the bias is
// options.ao_bias_mm when positive, else 3 % of the radius (it keeps flat open surfaces and the
// ripple of smoothed voxel surfaces from occluding themselves). docs/RENDERING.md has the
// measurements behind these numbers.
struct AoParameters {
  double radius_mm = 0, bias_mm = 0;
};
AoParameters ao_parameters(const RenderOptions& options, double visible_diagonal_mm);

// A rectangle of the target framebuffer, in its pixels, origin at the lower left (OpenGL).
struct Viewport {
  int x = 0, y = 0, width = 0, height = 0;
};

// Counts of the last frame, for a viewer's status line and for timing.
struct FrameStats {
  int parts_drawn = 0;
  int64_t triangles_drawn = 0;
  int64_t meshes_uploaded = 0;  // parts (re-)uploaded by this frame's sync
};

// Reads `viewport` of the framebuffer bound for reading now (a window's after drawing its UI, for
// a screenshot) as RGBA8, top row first. Needs a current context.
RgbaImage read_framebuffer(const Viewport& viewport);

class Renderer {
 public:
  // Compiles the shaders. Throws std::runtime_error when the context is not OpenGL 3.3 core
  // capable or a shader does not compile (an internal fault).
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Brings the GPU meshes up to date with the scene: uploads parts that are new or whose mesh
  // changed (by counts and a fingerprint of sampled vertices, indices, normals and colours) and
  // frees those of removed parts. Every draw call below does this first; call it yourself to
  // upload ahead of time.
  void sync(const Scene& scene);
  // Forces part `index` to be uploaded again by the next sync (after editing its mesh in place,
  // when the change might escape the fingerprint).
  void invalidate(size_t index);

  // Draws into the framebuffer bound when called (0: the window), into `viewport`. Renders into
  // the renderer's own buffers first, so the target needs no depth buffer. On return the
  // target framebuffer and the viewport are bound as they were; depth test, blending, culling,
  // scissor test and clip distances are off; no program, vertex array or texture binding on
  // units 0-2 is kept (a UI library that sets its own state, as Dear ImGui does, draws on top).
  void draw(const Scene& scene, const Camera& camera, const RenderOptions& options,
            const Viewport& viewport);

  // Renders offscreen into a width x height image (any size up to the driver's limit) and reads
  // it back: RGBA8, top row first.
  RgbaImage render_image(const Scene& scene, const Camera& camera, const RenderOptions& options,
                         int width, int height);

  // The part under every pixel of a width x height view (top row first): the index in
  // Scene::parts, -1 for the background. Visibility, transforms and the clipping plane count as
  // in draw(); transparent parts are found too.
  std::vector<int32_t> render_ids(const Scene& scene, const Camera& camera,
                                  const RenderOptions& options, int width, int height);

  // The part under pixel (x, y) of a width x height view (x right, y down from the top-left
  // pixel), or nullopt for the background or a pixel outside the view.
  std::optional<size_t> pick(const Scene& scene, const Camera& camera, const RenderOptions& options,
                             int width, int height, int x, int y);

  const FrameStats& last_frame() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace segmesh::render
