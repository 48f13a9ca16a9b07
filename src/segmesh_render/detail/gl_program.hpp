// Shader programs: compiling and linking GLSL sources (one way for every program, with the
// driver's log in the error), setting uniforms by name, and the one full-screen triangle the
// post-processing passes draw.
//
// Why: each pass of the renderer (ambient_occlusion, shading_pass, composite_pass, picking) owns
// the programs it draws with; this is what they share. Internal to segmesh_render.
// Guarantees: every program binds the mesh attributes to fixed locations (0 position, 1 normal,
// 2 colour), as the vertex arrays of gpu_mesh.hpp lay them out. Needs a current OpenGL 3.3 core
// context. Cost: compiling happens once per Renderer; a uniform set by name looks its location up
// each time, which costs nothing next to a frame (the programs are small).
#pragma once

#include <epoxy/gl.h>

#include <initializer_list>

#include "segmesh_render/detail/mat3.hpp"
#include "segmesh_render/mat4.hpp"

namespace segmesh::render {

// The program of `vertex` and `fragment` (GLSL sources). Throws std::runtime_error naming `name`
// and holding the driver's log when a shader does not compile or the program does not link (an
// internal fault: the sources are the renderer's own).
GLuint link_program(const char* vertex, const char* fragment, const char* name);

// Uniforms of program `p` (which must be in use) by name.
GLint uniform_location(GLuint p, const char* name);
void set_uniform(GLuint p, const char* name, int v);
void set_uniform(GLuint p, const char* name, float v);
void set_uniform(GLuint p, const char* name, float x, float y);
void set_uniform(GLuint p, const char* name, float x, float y, float z);
void set_uniform(GLuint p, const char* name, float x, float y, float z, float w);
void set_uniform(GLuint p, const char* name, const Mat4& m);
void set_uniform(GLuint p, const char* name, const Mat3& m);

// A sampler uniform and the 2D texture it reads.
struct Sampler {
  const char* name;
  GLuint texture;  // 0: none
};
// Binds the i-th texture to texture unit i and points its sampler uniform of `p` (in use) there;
// the last unit stays active.
void bind_samplers(GLuint p, std::initializer_list<Sampler> samplers);

// One triangle covering the viewport (shaders::fullscreen_vertex), drawn without attributes from
// an empty vertex array.
class FullscreenTriangle {
 public:
  FullscreenTriangle();
  ~FullscreenTriangle();
  FullscreenTriangle(const FullscreenTriangle&) = delete;
  FullscreenTriangle& operator=(const FullscreenTriangle&) = delete;

  // Uses `program` and draws the triangle into the bound framebuffer and viewport.
  void draw(GLuint program) const;

 private:
  GLuint vao_ = 0;
};

}  // namespace segmesh::render
