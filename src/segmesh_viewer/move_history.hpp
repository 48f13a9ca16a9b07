// Moving parts with undo, redo and reset — the "virtual removal" of an implant to see the bone
// beneath. Every move goes through here so the part's Transform (what the renderer draws and the
// GLB writer writes) always equals pose_transform(pose, pivot, base).
//
// A drag changes the pose many times a second but is one undoable step: the window calls
// preview_pose while dragging and commit_move with the pose from before the drag when the mouse
// is released. A field edit or a key is move_part (preview and commit at once). Any new move
// clears the redo list. Reset puts parts back where they were loaded, as one undoable step.
#pragma once

#include <cstddef>

#include "segmesh_viewer/viewer_state.hpp"

namespace segmesh::viewer {

// Sets part `index`'s pose (and its Transform) without recording it. Out-of-range: nothing.
void preview_pose(ViewerState& state, size_t index, const PartPose& pose);
// Records the change of part `index` from `before` to its current pose as one undoable step
// (nothing when they are equal).
void commit_move(ViewerState& state, size_t index, const PartPose& before);
// preview_pose + commit_move.
void move_part(ViewerState& state, size_t index, const PartPose& pose);

// Undoes / redoes the most recent step; false when there is none.
bool undo(ViewerState& state);
bool redo(ViewerState& state);
bool can_undo(const ViewerState& state);
bool can_redo(const ViewerState& state);

// Puts part `index` (reset_part) or every moved part (reset_moves) back to the identity pose, as
// one undoable step; false when nothing was moved.
bool reset_part(ViewerState& state, size_t index);
bool reset_moves(ViewerState& state);

}  // namespace segmesh::viewer
