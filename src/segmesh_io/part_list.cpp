#include "segmesh_io/part_list.hpp"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace segmesh::mesh_io {

void check_mesh(const Part& part) {
  const TriMesh& m = part.mesh;
  const auto bad = [&](const std::string& what) {
    throw std::invalid_argument("mesh of part '" + part.name + "': " + what);
  };
  if (m.indices.size() % 3 != 0) bad("index count is not a multiple of 3");
  if (!m.normals.empty() && m.normals.size() != m.positions.size()) bad("normals/positions differ");
  if (!m.colors.empty() && m.colors.size() != m.positions.size()) bad("colors/positions differ");
  if (m.positions.size() > std::numeric_limits<uint32_t>::max()) bad("too many vertices");
  const size_t n = m.positions.size();
  for (uint32_t i : m.indices) {
    if (i >= n) bad("index out of range");
  }
}

PartList parts_to_write(const Scene& scene) {
  PartList parts;
  for (const Part& part : scene.parts) {
    check_mesh(part);
    if (!part.mesh.empty()) parts.push_back(&part);
  }
  return parts;
}

}  // namespace segmesh::mesh_io
