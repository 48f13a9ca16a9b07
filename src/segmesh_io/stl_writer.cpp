#include "segmesh_io/stl_writer.hpp"

#include <algorithm>
#include <limits>

namespace segmesh {

using namespace mesh_io;

void write_stl(const PartList& parts, std::ostream& out, std::string_view name) {
  size_t triangles = 0;
  for (const Part* part : parts) triangles += part->mesh.triangle_count();
  if (triangles > std::numeric_limits<uint32_t>::max()) {
    throw Error("binary STL holds at most 4294967295 triangles; this scene has " +
                std::to_string(triangles) + " (write PLY or GLB instead)");
  }

  BlockWriter writer(out);
  std::string& buf = writer.buffer();
  // 3D Slicer reads "SPACE=LPS" in an STL header as the coordinate system of the file.
  const std::string_view suffix = " SPACE=LPS mm";
  std::string header = "segmesh " + one_line(name) + std::string(suffix);
  if (header.size() > 80) {
    header = "segmesh " + one_line(name).substr(0, 80 - 8 - suffix.size()) + std::string(suffix);
  }
  header.resize(80, ' ');
  buf += header;
  append_le<uint32_t>(buf, static_cast<uint32_t>(triangles));

  for (const Part* part : parts) {
    const PlacedMesh placed(*part);
    const TriMesh& m = placed.mesh();
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3f a = m.positions[m.indices[t]];
      const Vec3f b = m.positions[m.indices[t + 1]];
      const Vec3f c = m.positions[m.indices[t + 2]];
      for (const Vec3f& v : {face_normal(a, b, c), a, b, c}) {
        append_le(buf, v.x);
        append_le(buf, v.y);
        append_le(buf, v.z);
      }
      append_le<uint16_t>(buf, 0);
      writer.maybe_flush();
    }
  }
  writer.flush();
}

}  // namespace segmesh
