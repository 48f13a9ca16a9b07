// Writing a Scene's meshes to files: every part into one file, or one file per part.
//
// Formats and what each keeps (details in stl_writer.hpp, ply_writer.hpp, obj_writer.hpp,
// gltf_writer.hpp):
//   stl  binary STL: triangles only, all parts in one solid
//   ply  binary little-endian PLY: positions, normals, colours (material colour per part when
//        several parts share the file), part names and materials in header comments
//   obj  OBJ + MTL beside it: one object and one material per part, normals
//   glb  binary glTF 2.0: one node, mesh and PBR material per part, transforms, extras
// Coordinates are world millimetres in the LPS convention of the CT (glb adds a root node that
// converts to glTF's metres and +Y up). Formats without a scene graph (stl, ply, obj) write a part
// that has a non-identity Transform where it was moved to. Parts without triangles are skipped.
//
// Guarantees: every file is written atomically (a temporary file in the same folder, renamed when
// complete), so an error leaves neither the file nor a temporary behind. Errors are
// segmesh::Error with one line naming the path: a missing folder, no permission, a full disk, a
// scene too large for the format.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "segmesh/scene.hpp"
#include "segmesh_io/mesh_format.hpp"

namespace segmesh {


// How a scene is written, beyond its format.
struct MeshWriteOptions {
  // glb only: positions and normals quantized (KHR_mesh_quantization, gltf_writer.hpp), about
  // half the size, positions within 0.87 x the scene's largest extent / 65535. Another format
  // with quantize set is a segmesh::Error.
  bool quantize = false;
};

// Where a scene's meshes go, as `segmesh mesh -o OUTPUT [--format F]` says it (the Python
// package's write the same): a path ending in "/" or naming a folder is a folder with one file
// per part, in `format` ("" for ply); anything else one file whose extension names the format
// (`format`, when given, must agree). Throws segmesh::Error in one line: an unknown format or
// extension, a disagreement, a missing parent folder, options the format cannot carry
// (quantize without glb). Touches nothing on disk.
struct MeshTarget {
  std::filesystem::path path;  // the file, or the folder without its trailing "/"
  bool folder = false;
  MeshFormat format = MeshFormat::ply;
};
MeshTarget resolve_mesh_target(const std::string& output, const std::string& format,
                               const MeshWriteOptions& options);

// Writes every part of `scene` into `file` (OBJ: also `file` with the extension .mtl). The
// folder must exist.
void write_scene(const Scene& scene, const std::filesystem::path& file, MeshFormat format,
                 const MeshWriteOptions& options = {});

// Writes one file per part with triangles into `dir`, named after the part: characters other than
// ASCII letters, digits, '-', '_' and '.' become '_', leading dots are dropped, an empty name
// becomes "part", and repeated names (compared case-insensitively) get "_2", "_3", ... Creates
// `dir` when it is missing and its parent exists. Returns the files written, in part order (OBJ:
// the .obj files; each has its .mtl beside it). All files are written to temporaries first and
// renamed only when every part has been written, so an error while writing leaves nothing (and
// removes `dir` again if this call created it).
std::vector<std::filesystem::path> write_parts(const Scene& scene, const std::filesystem::path& dir,
                                               MeshFormat format,
                                               const MeshWriteOptions& options = {});

// The files write_parts would write, in the same order, without touching the disk.
std::vector<std::filesystem::path> part_file_paths(const Scene& scene,
                                                   const std::filesystem::path& dir,
                                                   MeshFormat format);

}  // namespace segmesh
