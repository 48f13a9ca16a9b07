// glTF 2.0 binary (.glb) writer, hand-written on nlohmann::json.
//
// Structure (passes the Khronos glTF validator with no errors or warnings):
//   scene 0 -> node "segmesh_scene" (the root) -> one node per part, named after the part.
//   Each part node holds a mesh (named after the part) with one triangle primitive: POSITION
//   (float VEC3 with min/max), NORMAL (float VEC3, re-normalised to unit length) when the part has
//   normals, COLOR_0 (normalised ubyte VEC4) when it has colours, uint32 indices, and a PBR
//   metallic-roughness material named after the part from Part::material. The part's Transform
//   becomes the node's matrix when it is not the identity. extras on the node: label, component,
//   role, voxels, voxel_volume_mm3, visible (hidden parts are written too). Parts without
//   triangles are skipped.
//
// Units and axes: accessor data stay in LPS millimetres (x = Left, y = Posterior, z = Superior),
// exactly the numbers of the TriMesh. glTF wants metres, +Y up and the asset facing +Z, so the
// root node's matrix is 0.001 * R with R mapping LPS to glTF as gltf = (x, z, -y): x stays Left
// (the viewer's right when the patient faces +Z), +Y is Superior, +Z is Anterior. R is a proper
// rotation, so triangle winding is unchanged. Column-major:
//   [0.001 0 0 0,  0 0 -0.001 0,  0 0.001 0 0,  0 0 0 1]
// asset.extras records {"units":"mm","space":"LPS","root_transform":...}; asset.generator is
// "segmesh". The file is laid out by detail/glb_document.hpp. Cost: one pass over the positions
// for their bounds, then the file is streamed (mesh_io::write_pieces): positions, colours and
// indices straight from the meshes, normals re-normalised piece by piece; the file is never
// assembled in memory.
//
// Quantized (`quantize`, `segmesh mesh --quantize`): KHR_mesh_quantization as
// detail/glb_document.hpp describes it: positions as 16-bit integers on one grid over the whole
// scene (a contact's shared vertices stay at one position in both parts), normals as 8-bit, uint16
// indices for parts of at most 65535 vertices; each part node's matrix gets the grid's scale and
// offset. The phantom's GLB shrinks to about half (docs/DECIMATION.md has the sizes).
#pragma once

#include <ostream>

#include "segmesh_io/part_list.hpp"

namespace segmesh {

// The root node's name and matrix (column-major), shared with the reader.
inline constexpr const char* kGltfRootName = "segmesh_scene";
inline constexpr Transform kGltfRootMatrix = {0.001, 0, 0, 0, 0, 0, -0.001, 0,
                                              0, 0.001, 0, 0, 0, 0, 0, 1};
// The inverse: glTF metres (+Y up, +Z front) to LPS millimetres.
inline constexpr Transform kGltfToLps = {1000, 0, 0, 0, 0, 0, 1000, 0, 0, -1000, 0, 0, 0, 0, 0, 1};

void write_glb(const mesh_io::PartList& parts, std::ostream& out, bool quantize = false);

}  // namespace segmesh
