// Part and Scene: what the pipeline produces, writers write and the viewer shows.
//
// A Part is one connected component of one label (or of a grey-value iso-surface), with its name,
// role, material and mesh in world millimetres. Parts of a label are numbered 1, 2, ... from the
// largest component down.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "segmesh/grid.hpp"
#include "segmesh/labelled_surface.hpp"
#include "segmesh/label_info.hpp"
#include "segmesh/transform.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

// glTF-style metallic-roughness material.
struct Material {
  Rgb base_color;
  float metallic = 0;
  float roughness = 0.6f;
};

// The look of a role: bone white and dielectric; implant red, metallic 1, roughness 0.7 (the
// reference viewer's implant material); other parts from `color` or a per-label palette colour.
Material default_material(Role role, int32_t label, std::optional<Rgb> color);

struct Part {
  std::string name;
  int32_t label = 0;
  int component = 1;  // 1 = the label's largest connected component
  Role role = Role::other;
  Material material;
  int64_t voxels = 0;             // voxels in this component
  double voxel_volume_mm3 = 0;    // voxels times the voxel volume
  TriMesh mesh;                   // world millimetres
  Transform transform = identity_transform();  // on top of the world coordinates (transform.hpp)
  bool visible = true;
};

// Every part's vertex positions as extracted, before smoothing moved them: smoothing keeps a
// mesh's triangles, so these positions with the part's own triangles are its surface before
// smoothing (for the report's volume change and smoothing deviation: scene_measures.hpp). 12
// bytes per vertex, where a copy of the meshes would take 24 per triangle more.
struct ExtractedPositions {
  std::vector<std::vector<Vec3f>> parts;  // in scene order
  // When the scene was decimated: every part's mesh before decimation (after smoothing), whose
  // positions `parts` are before smoothing; empty otherwise.
  std::vector<TriMesh> undecimated;
};

struct Scene {
  Grid grid;  // the source volume's grid
  std::vector<Part> parts;
  // Conforming surfaces: every contact between two parts is one surface of both. When some parts
  // touch, `surface` is the one surface of all parts (material p + 1 is parts[p]) and each part's
  // mesh is its shell (part_shells), remade whenever the surface changes (set_part_shells); when none
  // touch, there is no surface and each part was meshed on its own (the same result).
  bool conforming = false;
  std::optional<LabelledSurface> surface;
};

// Every part's mesh made anew from the scene's shared surface (precondition: it has one): its
// shell (part_shells), with its own vertex normals. Called whenever the surface changed. With
// `origin`, each shell vertex's surface vertex (part_shells).
void set_part_shells(Scene& scene, ShellOrigins* origin = nullptr);

}  // namespace segmesh
