// glTF 2.0 binary (.glb) reader, hand-written on nlohmann::json.
//
// Reads what segmesh writes (see gltf_writer.hpp) and common simple files: the GLB container with
// its JSON chunk and one BIN chunk; buffer 0 stored in the GLB; triangle primitives (mode 4,
// indexed with u8/u16/u32 indices or not indexed) with float VEC3 POSITION, float VEC3 NORMAL and
// COLOR_0 (float, or normalised ubyte/ushort; VEC3 or VEC4); matrix or TRS node transforms.
// KHR_mesh_quantization (what `segmesh mesh --quantize` writes): POSITION and NORMAL as 8- or
// 16-bit integers, normalised or not, turned into floats as the extension says.
// Anything else (external or data: URI buffers, sparse accessors, other primitive modes, required
// extensions such as Draco or meshopt compression, .gltf text files) is a clear segmesh::Error.
//
// Each node with a mesh becomes one Part named after the node (else its mesh), its primitives
// merged; material from the first primitive's pbrMetallicRoughness; label, component, role,
// voxels, voxel_volume_mm3 and visible from the node's extras when present. Coordinates: the
// node's world matrix is composed with the inverse of segmesh's root convention (glTF metres, +Y
// up, +Z front -> LPS millimetres). When that product is rigid it becomes Part::transform and the
// accessor data are kept as they are (so a segmesh file gives back its positions, indices and
// node matrices relative to "segmesh_scene" exactly); otherwise (scale, e.g. a file in metres
// without segmesh's root) it is baked into the positions and normals and the transform is the
// identity.
//
// Validation before allocation: chunk lengths against the file size, every buffer view against
// its buffer, every accessor's count * stride against its view, every index against the vertex
// count, node graphs for cycles. A lying file is a one-line segmesh::Error naming the file.
// Cost: one pass over the accessors.
#pragma once

#include <filesystem>
#include <string_view>

#include "segmesh/scene.hpp"

namespace segmesh {

// `bytes` is the whole file; `file` names it in error messages.
Scene read_glb(std::string_view bytes, const std::filesystem::path& file);

}  // namespace segmesh
