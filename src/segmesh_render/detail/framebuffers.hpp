// The renderer's offscreen framebuffers: textures, renderbuffers and framebuffer objects, and the
// three sets of them a Renderer keeps — the frame's buffers at the supersampled size, the part-id
// buffer for picking, and render_image's target.
//
// Why: the frame is drawn into the renderer's own buffers (so a window's framebuffer needs no
// depth buffer, and supersampling and ambient occlusion work at any target size) and composed
// into the caller's target at the end. Each set is made on first use and made again only when
// the size changes, so frames of one size allocate nothing.
// Guarantees: the textures sample with nearest filtering and clamp to the edge (every pass reads
// them texel for texel); a framebuffer that is not complete throws std::runtime_error (an
// internal fault). Needs a current OpenGL 3.3 core context, also to destroy a set.
#pragma once

#include <epoxy/gl.h>

#include <initializer_list>

namespace segmesh::render {

// A 2D texture of `internal` format, w x h, no mipmaps, nearest filtering, clamped; left bound to
// GL_TEXTURE_2D on the active unit.
GLuint make_texture(GLenum internal, GLenum format, GLenum type, int w, int h);

// A renderbuffer of `internal` format, w x h.
GLuint make_renderbuffer(GLenum internal, int w, int h);

// What a framebuffer attaches at one point: a 2D texture or a renderbuffer (0: nothing).
struct Attachment {
  GLuint texture = 0;
  GLuint renderbuffer = 0;
};

// A framebuffer drawing into `colors` (colour attachments 0, 1, ..., all of them draw buffers)
// with `depth` as its depth buffer; left bound to GL_FRAMEBUFFER.
GLuint make_framebuffer(std::initializer_list<Attachment> colors, Attachment depth = {});

// The frame's buffers, shared by its passes: at the internal (supersampled) size the depth and
// normal prepass (prepass_fbo: normal + depth) and the shaded colour (color_fbo: linear,
// premultiplied, on the same depth); at the output size (internal / samples) ambient occlusion and
// its blur (ao_fbo, blur_fbo, one channel each), so the occlusion costs the same and looks the same
// whatever the supersampling.
struct SceneTargets {
  int width = 0, height = 0;        // internal
  int ao_width = 0, ao_height = 0;  // output
  GLuint depth = 0, normal = 0, color = 0, ao = 0, blurred_ao = 0;  // textures
  GLuint prepass_fbo = 0, color_fbo = 0, ao_fbo = 0, blur_fbo = 0;

  SceneTargets() = default;
  ~SceneTargets() { release(); }
  SceneTargets(const SceneTargets&) = delete;
  SceneTargets& operator=(const SceneTargets&) = delete;

  // Makes the buffers for an internal size w x h (multiples of `samples`) when a size differs
  // from the last one.
  void ensure(int w, int h, int samples);
  void release();
};

// Part ids (index + 1, 0 for the background) with their own depth buffer, at the view's size.
struct IdTarget {
  int width = 0, height = 0;
  GLuint ids = 0;    // texture, R32UI
  GLuint depth = 0;  // renderbuffer
  GLuint fbo = 0;

  IdTarget() = default;
  ~IdTarget() { release(); }
  IdTarget(const IdTarget&) = delete;
  IdTarget& operator=(const IdTarget&) = delete;

  void ensure(int w, int h);
  void release();
};

// render_image's target: RGBA8 at the image's size, read back after the frame.
struct ImageTarget {
  int width = 0, height = 0;
  GLuint color = 0;  // renderbuffer
  GLuint fbo = 0;

  ImageTarget() = default;
  ~ImageTarget() { release(); }
  ImageTarget(const ImageTarget&) = delete;
  ImageTarget& operator=(const ImageTarget&) = delete;

  void ensure(int w, int h);
  void release();
};

}  // namespace segmesh::render
