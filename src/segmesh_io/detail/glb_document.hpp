// A GLB file described as plain data and written by one function: the machinery the GLB writers
// share (gltf_writer: a node and mesh per part; atlas_writer: one mesh, a primitive per pair of
// materials). Internal to segmesh_io; the JSON chunk is written as text (json_text.hpp), with no
// tree of values, so its cost per part is a small constant.
//
// The file (passes the Khronos glTF validator with no errors or warnings):
//   scene 0 -> the root node kGltfRootName, matrix kGltfRootMatrix (LPS millimetres to glTF
//   metres, +Y up; gltf_writer.hpp) -> one node per GlbMesh, in order, named after it, holding a
//   mesh of the same name. A mesh's vertices are stored once: POSITION (float VEC3 with exact
//   min/max), NORMAL (re-normalised to unit length) and COLOR_0 (normalised ubyte VEC4) when asked
//   for. Each primitive has its own uint32 index accessor over them, its material (a PBR
//   metallic-roughness material from a Material) and its extras. asset.extras records
//   {"units":"mm","space":"LPS","root_transform":...}; asset.generator is "segmesh".
// A mesh without primitives is skipped.
//
// Quantized (GlbScene::quantize, the KHR_mesh_quantization extension, listed as used and
// required): every mesh's positions are unsigned 16-bit integers on ONE grid over the whole scene
// (origin the scene's lowest corner, step its largest extent / 65535: 4.6 um for a 30 cm scene,
// so a position moves at most sqrt(3)/2 step), and each node's matrix gets the grid's scale and
// offset appended, so the file shows the same world millimetres. One grid keeps a vertex that two
// parts share (a contact of a conforming scene) at one position in both. Normals are normalised
// signed bytes (the rounding of the 8 candidates nearest to the unit normal that is closest to
// unit length, within the validator's 0.00674), each attribute padded to 4 bytes; indices are
// uint16 when the mesh has at most 65535 vertices. About 22 bytes per vertex and triangle become
// 12 (positions 8, normals 4) and 6 or 12.
//
// Cost: one pass over each mesh's positions for their bounds, then the file is streamed
// (piece_writer.hpp): positions, colours and indices straight from the memory they live in,
// normals re-normalised piece by piece; the file is never assembled in memory.
#pragma once

#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "segmesh/scene.hpp"

namespace segmesh::mesh_io {

// A value of a glTF extras object; the members are written in the order given. Keys are string
// literals (or outlive the write).
using GlbValue = std::variant<bool, int64_t, double, std::string>;
using GlbExtras = std::vector<std::pair<std::string_view, GlbValue>>;

struct GlbPrimitive {
  std::span<const uint32_t> indices;  // 3 per triangle, into the mesh's vertices; kept alive
                                      // by the caller until the file is written
  size_t material = 0;                // index into GlbScene::materials
  GlbExtras extras;                   // written when not empty
};

struct GlbMesh {
  std::string name;                   // the node's and the mesh's
  const TriMesh* vertices = nullptr;  // positions (and normals, colours) all primitives share
  bool normals = false;               // write NORMAL (vertices->normals must be filled)
  bool colors = false;                // write COLOR_0 (vertices->colors must be filled)
  std::vector<GlbPrimitive> primitives;
  Transform matrix = identity_transform();  // the node's, written when not the identity
  GlbExtras extras;                         // the node's, written when not empty
};

struct GlbMaterial {
  std::string name;
  Material material;
};

struct GlbScene {
  std::vector<GlbMaterial> materials;
  std::vector<GlbMesh> meshes;
  bool quantize = false;  // KHR_mesh_quantization, as said above
};

// Throws segmesh::Error when a mesh has too many vertices for uint32 indices or the file would
// pass the format's 4 GiB.
void write_glb_scene(const GlbScene& scene, std::ostream& out);

}  // namespace segmesh::mesh_io
