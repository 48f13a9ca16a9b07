// Picking: the part under each pixel, drawn as ids (part index + 1, 0 for the background) into an
// integer buffer at the view's own size and read back, for Renderer::render_ids and
// Renderer::pick.
//
// Why: the viewer selects a part by clicking it; drawing ids with the frame's own matrices and
// clipping plane finds exactly the part the picture shows there, transparent parts included.
// Guarantees: the same parts, transforms, visibility and cut as draw() (frame.hpp), the nearest
// surface winning; a pick draws only its one pixel (scissor). Cost: one draw per part, at most
// width x height pixels, and a read back (a whole view, or one pixel). Needs a current OpenGL
// 3.3 core context, also for the destructor.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "segmesh_render/detail/frame.hpp"
#include "segmesh_render/detail/framebuffers.hpp"

namespace segmesh::render {

class Picking {
 public:
  Picking();  // links the program
  ~Picking();
  Picking(const Picking&) = delete;
  Picking& operator=(const Picking&) = delete;

  // Draws the ids of `f` (its size is the view's) into the id buffer; only the pixels of
  // `scissor` (x, y from the bottom, width, height) when given.
  void render(const Frame& f, const std::array<int, 4>* scissor);

  // After render: the part index of every pixel, top row first, -1 for the background.
  std::vector<int32_t> read_all() const;
  // After render: the part index at pixel (x, gl_y), gl_y counted from the bottom row, or nullopt
  // for the background.
  std::optional<size_t> read_pixel(int x, int gl_y) const;

 private:
  GLuint id_ = 0;  // program
  IdTarget target_;
};

}  // namespace segmesh::render
