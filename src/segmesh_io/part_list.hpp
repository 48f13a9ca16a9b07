// The input of every per-format mesh writer (stl_writer, ply_writer, obj_writer, gltf_writer):
// the parts of a scene that have triangles, in scene order, each checked first.
#pragma once

#include <vector>

#include "segmesh/scene.hpp"

namespace segmesh::mesh_io {

// Pointers, so write_mesh can hand one part to a writer without copying its mesh.
using PartList = std::vector<const Part*>;

// The parts with at least one triangle (empty parts are skipped by every writer). Checks each
// part's arrays (sizes agree, indices in range) and throws std::invalid_argument for a malformed
// mesh: that is a programming fault, not a user error. One pass over the indices.
PartList parts_to_write(const Scene& scene);
void check_mesh(const Part& part);

}  // namespace segmesh::mesh_io
