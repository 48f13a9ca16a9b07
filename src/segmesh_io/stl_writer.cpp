#include "segmesh_io/stl_writer.hpp"

#include <algorithm>
#include <array>
#include <limits>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"

namespace segmesh {

using namespace mesh_io;

void write_stl(const PartList& parts, std::ostream& out, std::string_view name) {
  size_t triangles = 0;
  for (const Part* part : parts) triangles += part->mesh.triangle_count();
  if (triangles > std::numeric_limits<uint32_t>::max()) {
    throw Error("binary STL holds at most 4294967295 triangles; this scene has " +
                std::to_string(triangles) + " (write PLY or GLB instead)");
  }

  // 3D Slicer reads "SPACE=LPS" in an STL header as the coordinate system of the file.
  const std::string_view suffix = " SPACE=LPS mm";
  std::string header = "segmesh " + one_line(name) + std::string(suffix);
  if (header.size() > 80) {
    header = "segmesh " + one_line(name).substr(0, 80 - 8 - suffix.size()) + std::string(suffix);
  }
  header.resize(80, ' ');
  append_le<uint32_t>(header, static_cast<uint32_t>(triangles));

  PieceList pieces;
  pieces.text(std::move(header));
  for (const Part* part : parts) {
    const TriMesh& m = part->mesh;
    const Placement placement(*part);
    pieces.items(m.triangle_count(), kPieceBytes / 50,
                 [&m, placement](size_t begin, size_t end, ChunkBuffer& buffer) {
                   char* p = buffer.room((end - begin) * 50);
                   for (size_t t = begin; t < end; ++t) {
                     const std::array<uint32_t, 3> c = placement.corners(m, t);
                     const Vec3f a = placement.point(m.positions[c[0]]);
                     const Vec3f b = placement.point(m.positions[c[1]]);
                     const Vec3f d = placement.point(m.positions[c[2]]);
                     for (const Vec3f& v : {face_normal(a, b, d), a, b, d}) {
                       p = put_le(p, v.x);
                       p = put_le(p, v.y);
                       p = put_le(p, v.z);
                     }
                     p = put_le<uint16_t>(p, 0);
                   }
                   buffer.commit(p);
                   return buffer.view();
                 });
  }
  pieces.write(out);
}

}  // namespace segmesh
