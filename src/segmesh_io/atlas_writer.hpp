// Atlas export: a scene's conforming surface (Scene::surface, built by --surfaces conforming) in
// one file, the surface multi-domain volume meshers (CGAL, TetGen, fTetWild, Gmsh) start from.
// When no two parts of a conforming scene touch there is no Scene::surface (extract_parts meshed
// the parts one by one, the same surfaces); the atlas is then the parts' shells, every triangle
// between its part and the background, from a copy of the meshes.
//
// The atlas is ONE mesh for all parts (labelled_surface.hpp): vertices shared between parts, each
// triangle tagged with the two materials it separates, {inside, outside}, where 0 is the
// background and p + 1 is scene.parts[p], and wound counter-clockwise seen from its outside
// material. It is not a manifold: an edge where three or more materials meet carries three or
// more triangles. Coordinates are world millimetres, LPS, exactly as the surface holds them; the
// parts' Transforms are not applied (moving one part would break its contacts). No normals or
// colours are written: at a contact a vertex lies on two parts' surfaces.
//
// Formats, by extension (case-insensitive):
//   .ply  binary little-endian. The header starts as ply_writer's (SPACE=LPS, units mm), then one
//         comment per material: "comment material 0 background", "comment material 1 <part
//         name>", ... Vertices: float x y z. Faces: "property list uchar int vertex_indices",
//         "property int inside", "property int outside" (material numbers).
//   .glb  glTF 2.0 binary laid out as gltf_writer's (detail/glb_document.hpp: the root node maps
//         LPS millimetres to glTF metres, +Y up): one node and mesh "atlas" with one triangle
//         primitive per (inside, outside) pair present, in ascending pair order, each with its own
//         index accessor over ONE POSITION accessor shared by all primitives; the triangles keep
//         their surface order within a primitive. Each primitive's extras name its pair:
//         {"inside": "label1_1", "outside": "background", "inside_material": 1,
//          "outside_material": 0}; its material is the inside part's (the outside part's when the
//         inside is the background), named after the part.
//
// Guarantees: written atomically (AtomicFile), so an error leaves neither the file nor a
// temporary. Errors are one-line segmesh::Error naming the file: an extension other than .ply or
// .glb, a scene of independent surfaces ("... --atlas needs --surfaces conforming"), a missing
// folder, a full disk, more vertices than the format's indices hold. A surface whose arrays
// disagree (sides, indices, materials beyond the parts) is std::invalid_argument, a programming
// fault.
// Cost: one pass over the surface, streamed in pieces formatted in parallel; the GLB first groups
// the triangles by pair, a copy of the indices (12 bytes per triangle).
#pragma once

#include <filesystem>

#include "segmesh/scene.hpp"

namespace segmesh {

enum class AtlasFormat { ply, glb };

// The format `file`'s extension names; throws segmesh::Error for anything but .ply and .glb.
AtlasFormat atlas_format(const std::filesystem::path& file);

void write_atlas(const Scene& scene, const std::filesystem::path& file);

}  // namespace segmesh
