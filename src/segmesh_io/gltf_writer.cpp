#include "segmesh_io/gltf_writer.hpp"

#include "segmesh_io/detail/glb_document.hpp"

namespace segmesh {

using namespace mesh_io;

void write_glb(const PartList& parts, std::ostream& out, bool quantize) {
  GlbScene scene;
  scene.quantize = quantize;
  for (const Part* part_ptr : parts) {
    const Part& part = *part_ptr;
    const TriMesh& m = part.mesh;
    scene.materials.push_back(GlbMaterial{part.name, part.material});
    scene.meshes.push_back(GlbMesh{
        .name = part.name,
        .vertices = &m,
        .normals = !m.normals.empty(),
        .colors = !m.colors.empty(),
        .primitives = {GlbPrimitive{m.indices, scene.materials.size() - 1, {}}},
        .matrix = part.transform,
        .extras = {{"label", int64_t{part.label}},
                   {"component", int64_t{part.component}},
                   {"role", std::string(role_name(part.role))},
                   {"voxels", int64_t{part.voxels}},
                   {"voxel_volume_mm3", part.voxel_volume_mm3},
                   {"visible", part.visible}}});
  }
  write_glb_scene(scene, out);
}

}  // namespace segmesh
