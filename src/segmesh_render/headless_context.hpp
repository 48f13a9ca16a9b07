// HeadlessContext: an OpenGL 3.3 core context with no window and no display server, for rendering
// pictures from the command line, in tests and in CI.
//
// It is made through EGL (loaded at run time by libepoxy), trying in turn: Mesa's surfaceless
// platform (EGL_MESA_platform_surfaceless: llvmpipe on a machine without a GPU, the GPU's Mesa
// driver otherwise), the EGL devices (EGL_EXT_platform_device: a GPU driver that is not Mesa's),
// and the default display with a 1x1 pbuffer. The renderer draws into its own framebuffer objects,
// so the context never needs a default framebuffer of any size.
//
// A viewer does not need this class: it makes its window's context current (GLFW) and hands the
// Renderer nothing else.
#pragma once

#include <string>

namespace segmesh::render {

class HeadlessContext {
 public:
  // Creates the context and makes it current on the calling thread. Throws segmesh::Error with
  // one line saying why when no context can be made ("cannot create an OpenGL 3.3 context
  // without a display: ...; install Mesa's EGL and drivers (libegl1, libegl-mesa0,
  // libgl1-mesa-dri)").
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  // Makes the context current on the calling thread (after another context was).
  void make_current();

  // "OpenGL 4.5 (Core Profile) Mesa 22.3.6 on llvmpipe (LLVM 15.0.6, 256 bits) (surfaceless)".
  const std::string& description() const { return description_; }

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;  // the pbuffer, when that path was taken
  std::string description_;
};

}  // namespace segmesh::render
