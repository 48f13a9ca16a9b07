#include "segmesh_io/ply_writer.hpp"

#include <array>
#include <limits>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"
#include "segmesh_io/detail/ply_layout.hpp"

namespace segmesh {

using namespace mesh_io;

void write_ply(const PartList& parts, std::ostream& out) {
  size_t vertices = 0, faces = 0;
  bool all_normals = !parts.empty(), any_colors = false;
  for (const Part* part : parts) {
    vertices += part->mesh.vertex_count();
    faces += part->mesh.triangle_count();
    all_normals = all_normals && !part->mesh.normals.empty();
    any_colors = any_colors || !part->mesh.colors.empty();
  }
  if (vertices > std::numeric_limits<uint32_t>::max()) {
    throw Error("PLY with uint32 indices holds at most 4294967295 vertices; this scene has " +
                std::to_string(vertices));
  }
  const PlyVertexLayout layout{.normals = all_normals, .colors = any_colors || parts.size() > 1};

  std::string header = ply_header_start();
  for (const Part* part : parts) {
    const Material& m = part->material;
    header += "comment part vertices=" + std::to_string(part->mesh.vertex_count()) +
              " faces=" + std::to_string(part->mesh.triangle_count()) +
              " label=" + std::to_string(part->label) + " component=" + std::to_string(part->component) +
              " role=" + std::string(role_name(part->role)) + " voxels=" + std::to_string(part->voxels) +
              " visible=" + (part->visible ? "1" : "0") + " color=" + format_float(m.base_color.r) + "," +
              format_float(m.base_color.g) + "," + format_float(m.base_color.b) +
              " metallic=" + format_float(m.metallic) + " roughness=" + format_float(m.roughness) +
              " name=" + one_line(part->name) + "\n";
  }
  header += ply_vertex_element(vertices, layout);
  header += "element face " + std::to_string(faces) + "\n";
  header += "property list uchar uint vertex_indices\nend_header\n";

  PieceList pieces;
  pieces.text(std::move(header));
  for (const Part* part : parts) {
    const Rgba8 material_color{to_unorm8(part->material.base_color.r),
                               to_unorm8(part->material.base_color.g),
                               to_unorm8(part->material.base_color.b), 255};
    add_ply_vertices(pieces, part->mesh, Placement(*part), layout, material_color);
  }
  uint32_t first = 0;
  for (const Part* part : parts) {
    const TriMesh& m = part->mesh;
    // Baking a mirroring transform into the coordinates must also reverse the winding.
    const Placement placement(*part);
    pieces.records(m.triangle_count(), 13, [&m, placement, first](size_t t, char* p) {
      const std::array<uint32_t, 3> c = placement.corners(m, t);
      *p++ = 3;
      p = put_le<uint32_t>(p, first + c[0]);
      p = put_le<uint32_t>(p, first + c[1]);
      return put_le<uint32_t>(p, first + c[2]);
    });
    first += static_cast<uint32_t>(m.vertex_count());
  }
  pieces.write(out);
}

}  // namespace segmesh
