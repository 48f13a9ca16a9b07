#include "segmesh_viewer/move_history.hpp"

#include "segmesh_viewer/part_pose.hpp"

namespace segmesh::viewer {

namespace {

void record(ViewerState& state, MoveEdit edit) {
  if (edit.changes.empty()) return;
  state.history.undo.push_back(std::move(edit));
  state.history.redo.clear();
}

}  // namespace

void preview_pose(ViewerState& state, size_t index, const PartPose& pose) {
  if (index >= state.scene.parts.size() || index >= state.views.size()) return;
  PartView& view = state.views[index];
  view.pose = pose;
  state.scene.parts[index].transform = pose_transform(pose, view.pivot, view.base);
}

void commit_move(ViewerState& state, size_t index, const PartPose& before) {
  if (index >= state.views.size()) return;
  const PartPose& after = state.views[index].pose;
  if (after == before) return;
  record(state, MoveEdit{{{index, before, after}}});
}

void move_part(ViewerState& state, size_t index, const PartPose& pose) {
  if (index >= state.views.size()) return;
  const PartPose before = state.views[index].pose;
  preview_pose(state, index, pose);
  commit_move(state, index, before);
}

bool can_undo(const ViewerState& state) { return !state.history.undo.empty(); }
bool can_redo(const ViewerState& state) { return !state.history.redo.empty(); }

bool undo(ViewerState& state) {
  if (state.history.undo.empty()) return false;
  MoveEdit edit = std::move(state.history.undo.back());
  state.history.undo.pop_back();
  for (const MoveEdit::Change& c : edit.changes) preview_pose(state, c.part, c.before);
  state.history.redo.push_back(std::move(edit));
  return true;
}

bool redo(ViewerState& state) {
  if (state.history.redo.empty()) return false;
  MoveEdit edit = std::move(state.history.redo.back());
  state.history.redo.pop_back();
  for (const MoveEdit::Change& c : edit.changes) preview_pose(state, c.part, c.after);
  state.history.undo.push_back(std::move(edit));
  return true;
}

bool reset_part(ViewerState& state, size_t index) {
  if (index >= state.views.size() || state.views[index].pose == PartPose{}) return false;
  move_part(state, index, PartPose{});
  return true;
}

bool reset_moves(ViewerState& state) {
  MoveEdit edit;
  for (size_t i = 0; i < state.views.size(); ++i) {
    if (state.views[i].pose == PartPose{}) continue;
    edit.changes.push_back({i, state.views[i].pose, PartPose{}});
    preview_pose(state, i, PartPose{});
  }
  const bool any = !edit.changes.empty();
  record(state, std::move(edit));
  return any;
}

}  // namespace segmesh::viewer
