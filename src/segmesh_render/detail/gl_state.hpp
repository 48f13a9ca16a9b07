// The caller's OpenGL state around a renderer call: what is saved on entry (the draw and read
// framebuffers, the viewport) and what the caller gets back on exit.
//
// Why: the viewer draws its UI (Dear ImGui) into the same window after the renderer, and a
// command-line caller reads the picture back; both need their framebuffer and viewport as they
// left them, and the renderer's own state switched off. This is the promise renderer.hpp makes
// for draw(), render_image(), render_ids() and pick().
// Guarantees: on restore the saved framebuffers and viewport are bound again; depth test,
// blending, culling and clip distance 0 are off, depth func GL_LESS with writes on, no program,
// vertex array or 2D texture on units 0-2 is bound, and unit 0 is active. Cost: a few state
// calls. Needs a current OpenGL 3.3 core context.
#pragma once

#include <epoxy/gl.h>

namespace segmesh::render {

struct SavedTarget {
  GLint draw = 0, read = 0, viewport[4] = {0, 0, 0, 0};
};

SavedTarget save_target();
void restore_target(const SavedTarget& s);

}  // namespace segmesh::render
