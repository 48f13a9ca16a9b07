#include "segmesh/detail/decimation_blocks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "segmesh/mesh_measures.hpp"

namespace segmesh {

double decimation_block_side(const DecimationMesh& m, size_t per_block) {
  const size_t nv = m.pos.size();
  const double area = surface_area(m.s.mesh);  // before any collapse: m.pos are its positions
  const double side = std::sqrt(area * double(per_block) / double(std::max<size_t>(1, nv)));
  return side > 0 && std::isfinite(side) ? side : 0;
}

DecimationBlocks decimation_blocks(const DecimationMesh& m, double side, double shift,
                                   size_t materials, size_t max_entries) {
  const size_t nv = m.pos.size(), nt = m.s.sides.size();
  DecimationBlocks out;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  Vec3d lo{kInfinity, kInfinity, kInfinity}, hi = -1.0 * lo;
  for (size_t v = 0; v < nv; ++v) {
    if (!m.alive_vertex[v]) continue;
    const Vec3d& p = m.pos[v];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  if (!(side > 0) || !(lo.x <= hi.x)) return out;
  lo = lo - shift * side * Vec3d{1, 1, 1};
  const Vec3d extent = hi - lo;
  const double cells = std::floor(extent.x / side + 1) * std::floor(extent.y / side + 1) *
                       std::floor(extent.z / side + 1);
  if (!(cells <= double(max_entries))) return out;
  const size_t nx = size_t(extent.x / side) + 1, ny = size_t(extent.y / side) + 1,
               nz = size_t(extent.z / side) + 1;
  // Each live vertex's cell, then the cells that hold vertices numbered in grid order.
  std::vector<uint32_t> block_of_cell(nx * ny * nz, ~0u), owner(nv, DecimationBlocks::kBorder);
  for (size_t v = 0; v < nv; ++v) {
    if (!m.alive_vertex[v]) continue;
    const Vec3d d = m.pos[v] - lo;
    owner[v] = uint32_t(
        (std::min(size_t(d.z / side), nz - 1) * ny + std::min(size_t(d.y / side), ny - 1)) * nx +
        std::min(size_t(d.x / side), nx - 1));
    block_of_cell[owner[v]] = 0;
  }
  uint32_t blocks = 0;
  for (uint32_t& b : block_of_cell)
    if (b == 0) b = blocks++;
  if (blocks < 2 || size_t(blocks) * materials > max_entries) return out;
  for (size_t v = 0; v < nv; ++v)
    if (m.alive_vertex[v]) owner[v] = block_of_cell[owner[v]];
  // The core: vertices with no triangle across blocks. The sides each block owns.
  out.count = blocks;
  out.core = owner;
  out.sides.assign(size_t(blocks) * materials, 0);
  auto owned_by = [&](const uint32_t* i) {
    return owner[i[1]] == owner[i[0]] && owner[i[2]] == owner[i[0]] ? owner[i[0]] : ~0u;
  };
  for (size_t t = 0; t < nt; ++t) {
    if (!m.alive_tri[t]) continue;
    const uint32_t* i = &m.s.mesh.indices[3 * t];
    const uint32_t b = owned_by(i);
    if (b == ~0u) {
      for (int k = 0; k < 3; ++k) out.core[i[k]] = DecimationBlocks::kBorder;
      continue;
    }
    for (uint32_t mat : m.s.sides[t])
      if (mat != 0) ++out.sides[size_t(b) * materials + mat];
  }
  // Locked sides: their triangle has two corners or more on or next to the border.
  std::vector<char> near(nv, 0);
  for (size_t t = 0; t < nt; ++t) {
    if (!m.alive_tri[t]) continue;
    const uint32_t* i = &m.s.mesh.indices[3 * t];
    if (out.core[i[0]] == DecimationBlocks::kBorder ||
        out.core[i[1]] == DecimationBlocks::kBorder || out.core[i[2]] == DecimationBlocks::kBorder)
      near[i[0]] = near[i[1]] = near[i[2]] = 1;
  }
  out.locked.assign(blocks, 0);
  for (size_t t = 0; t < nt; ++t) {
    if (!m.alive_tri[t]) continue;
    const uint32_t* i = &m.s.mesh.indices[3 * t];
    const uint32_t b = owned_by(i);
    if (b == ~0u || near[i[0]] + near[i[1]] + near[i[2]] < 2) continue;
    for (uint32_t mat : m.s.sides[t]) out.locked[b] += mat != 0;
  }
  out.vertices.resize(blocks);
  for (uint32_t v = 0; v < nv; ++v)
    if (out.core[v] != DecimationBlocks::kBorder) out.vertices[out.core[v]].push_back(v);
  return out;
}

bool in_block_core(const DecimationMesh& m, const std::vector<uint32_t>& core, uint32_t u,
                   uint32_t v, uint32_t block) {
  if (core[u] != block || core[v] != block) return false;
  for (uint32_t x : {u, v})
    for (uint32_t t : m.tris[x]) {
      if (!m.alive_tri[t]) continue;
      const uint32_t* i = &m.s.mesh.indices[3 * size_t(t)];
      if (core[i[0]] != block || core[i[1]] != block || core[i[2]] != block) return false;
    }
  return true;
}

}  // namespace segmesh
