// Saving the viewer's scene as binary glTF, as it is shown: every part with its current Transform
// (the user's move, written as the part node's matrix by the GLB writer, gltf_writer.hpp), its
// current colour as the material's base colour, and its visibility.
//
// Hidden parts are written too, marked hidden (node extras "visible": false), not left out: the
// saved file is the whole plan, and read_mesh (so segmesh-viewer and `segmesh render`) opens it
// with the same parts hidden. A glTF viewer that ignores extras shows them. Opacity is a view
// setting and is not saved. Parts without triangles are skipped by the writer. The file is written
// atomically (a failed save leaves no file behind). Throws segmesh::Error naming the file.
#pragma once

#include <filesystem>

#include "segmesh_viewer/viewer_state.hpp"

namespace segmesh::viewer {

// `file` must end in .glb (any case) and its folder must exist.
void save_scene_glb(const ViewerState& state, const std::filesystem::path& file);

}  // namespace segmesh::viewer
