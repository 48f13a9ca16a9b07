// ViewerState: everything the planning viewer shows and edits, as plain data — the scene of parts
// (mesh, material colour, transform, visibility live in segmesh::Part), and per part the opacity,
// the move the user made and its statistics; the selection; the undo history of moves; the volume
// the scene was meshed from (kept for "Create mesh" with other options) and a status message.
//
// The functions here are the small edits a panel makes (select, show/hide, colour, opacity) and
// replacing the whole scene after a load. Moves and their history are in move_history.hpp, the
// geometry of a move in part_pose.hpp. No window, no OpenGL: tests drive it directly.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/vec3.hpp"
#include "segmesh_viewer/part_stats.hpp"

namespace segmesh::viewer {

// A move of a part, as the translate and rotate fields show it: a rotation about the part's
// centre (degrees about the world x, then y, then z axis) followed by a translation (world mm).
// The identity pose leaves the part where it was loaded.
struct PartPose {
  Vec3d translation_mm{0, 0, 0};
  Vec3d rotation_deg{0, 0, 0};
};
bool operator==(const PartPose& a, const PartPose& b);  // exact comparison of all six numbers

// What the viewer keeps per part beside segmesh::Part.
struct PartView {
  float opacity = 1;                     // 0..1, handed to RenderOptions::opacity
  PartPose pose;                         // the user's move
  Transform base = identity_transform(); // the transform the part was loaded with (a GLB node)
  Vec3d pivot{0, 0, 0};                  // rotation centre: the centre of the placed part's bounds
};

// One undoable step: the poses of some parts before and after (one part for a drag or a field
// edit, every moved part for "reset all").
struct MoveEdit {
  struct Change {
    size_t part = 0;
    PartPose before, after;
  };
  std::vector<Change> changes;
};

struct MoveHistory {
  std::vector<MoveEdit> undo;  // most recent last
  std::vector<MoveEdit> redo;  // most recently undone last
};

struct ViewerState {
  Scene scene;
  std::vector<PartView> views;    // one per part of scene.parts
  std::vector<PartStats> stats;   // one per part (may be empty until measured)
  int selected = -1;              // index into scene.parts, -1: none
  MoveHistory history;
  std::string source;             // the file the scene came from ("" before the first load)
  std::shared_ptr<const Image> image;  // the volume the scene was meshed from (null for a mesh file)
  std::string surfaces;           // which surfaces the meshing made (surfaces_summary); "" otherwise
  std::string message;            // the last status or error line for the window
  bool message_is_error = false;
};

// Replaces the scene (after a load or a meshing): poses reset, each part's loaded transform kept
// as its base, selection and history cleared, opacity 1, the surfaces line cleared (finish_load
// sets it for a meshed volume). `stats` may be empty (then measured here).
void set_scene(ViewerState& state, Scene scene, std::vector<PartStats> stats, std::string source,
               std::shared_ptr<const Image> image);

// Selects part `index`, or nothing for -1 or an index out of range.
void select_part(ViewerState& state, int index);
// Shows or hides a part; hiding the selected part clears the selection.
void set_visible(ViewerState& state, size_t index, bool visible);
void set_opacity(ViewerState& state, size_t index, float opacity);  // clamped to [0, 1]
void set_color(ViewerState& state, size_t index, Rgb color);        // the material's base colour

// The per-part opacities in the form RenderOptions::opacity takes.
std::vector<float> render_opacity(const ViewerState& state);

// Sets the status line (`error` true for a problem the user should read).
void set_message(ViewerState& state, std::string message, bool error = false);

}  // namespace segmesh::viewer
