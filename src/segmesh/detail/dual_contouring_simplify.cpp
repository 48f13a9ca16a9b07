#include "segmesh/detail/dual_contouring_simplify.hpp"

#include <algorithm>
#include <cmath>

#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/morton.hpp"

namespace segmesh {

namespace {

struct Node {
  uint64_t key = 0;
  bool collapsible = false;
  Qef qef;          // in the node's frame: origin at its first cell's corner, mm
  Vec3d normal_sum;
  Vec3d position;   // the collapsed vertex, node frame (valid when collapsible, level >= 1)
  int64_t rep = -1;  // vertex id of the highest collapsed ancestor (or itself)
  uint32_t first_vertex = 0;  // level 0: the cell's first sheet vertex
};

// Ju et al.'s topology-safety test and the single-sheet test for the node of `size` cells at
// cell `origin`.
bool topology_safe(const DcCells& cells, const DcTable& table, std::array<int64_t, 3> o, int64_t size) {
  for (int a = 0; a < 3; ++a) {
    if (o[a] + size > cells.cells[a]) return false;  // the node sticks out of the field
  }
  const int64_t h = size / 2;
  // Signs on the node's 3x3x3 lattice of corners, edge midpoints, face centres and centre.
  bool s[3][3][3];
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) s[z][y][x] = cells.inside(o[0] + x * h, o[1] + y * h, o[2] + z * h);
  int cs = 0;
  for (int c = 0; c < 8; ++c) {
    const auto& off = kMcCornerOffset[c];
    cs |= s[2 * off[2]][2 * off[1]][2 * off[0]] << c;
  }
  if (table.cases[cs].piece_count != 1) return false;
  // Every lattice point that is not a corner must share its sign with at least one of the corners
  // of the edge, face or cube it is the centre of.
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) {
        if (x != 1 && y != 1 && z != 1) continue;  // a corner
        bool match = false;
        for (int cz = (z == 1 ? 0 : z); cz <= (z == 1 ? 2 : z); cz += 2)
          for (int cy = (y == 1 ? 0 : y); cy <= (y == 1 ? 2 : y); cy += 2)
            for (int cx = (x == 1 ? 0 : x); cx <= (x == 1 ? 2 : x); cx += 2)
              match = match || s[cz][cy][cx] == s[z][y][x];
        if (!match) return false;
      }
  return true;
}

}  // namespace

TriMesh simplify_dual_contour(TriMesh mesh, const DcCells& cells, const Grid& grid,
                              const DcOptions& o) {
  const DcTable& table = dc_table(o.connectivity);
  const auto& s = grid.spacing;

  // Level 0: the cells the surface crosses.
  std::vector<std::vector<Node>> levels(1);
  for (const SurfaceCell& c : cells.surface) {
    const int pieces = table.cases[c.cs].piece_count;
    Node n;
    n.key = morton(c.i, c.j, c.k);
    n.collapsible = pieces == 1;
    n.first_vertex = c.first_vertex;
    if (pieces == 1) {
      n.qef = (*cells.qefs)[c.first_vertex];
      n.normal_sum = to_double(mesh.normals[c.first_vertex]);
    }
    levels[0].push_back(n);
  }
  std::sort(levels[0].begin(), levels[0].end(),
            [](const Node& a, const Node& b) { return a.key < b.key; });

  // Levels 1, 2, ...: a node per group of children sharing key >> 3.
  while (levels.back().size() > 1) {
    const std::vector<Node>& children = levels.back();
    const int level = static_cast<int>(levels.size());
    const int64_t size = int64_t{1} << level;
    std::vector<Node> parents;
    bool any_collapsed = false;
    for (size_t a = 0; a < children.size();) {
      size_t b = a;
      Node parent;
      parent.key = children[a].key >> 3;
      bool children_ok = true;
      while (b < children.size() && (children[b].key >> 3) == parent.key) {
        children_ok = children_ok && children[b].collapsible;
        ++b;
      }
      const auto c3 = unmorton(parent.key);
      const std::array<int64_t, 3> origin{c3[0] * size, c3[1] * size, c3[2] * size};
      if (children_ok && topology_safe(cells, table, origin, size)) {
        for (size_t c = a; c < b; ++c) {
          const auto cc = unmorton(children[c].key);
          const int64_t child_size = size / 2;
          const Vec3d d{double(cc[0] * child_size - origin[0]) * s[0],
                        double(cc[1] * child_size - origin[1]) * s[1],
                        double(cc[2] * child_size - origin[2]) * s[2]};
          parent.qef.merge(children[c].qef.translated(d));
          parent.normal_sum = parent.normal_sum + children[c].normal_sum;
        }
        const QefSolution sol = solve_qef(parent.qef, o.svd_eps);
        const double m = kDcCellMargin * double(size);
        parent.position =
            keep_in_box(sol.position, parent.qef.mass_point(), {m * s[0], m * s[1], m * s[2]},
                        {(size - m) * s[0], (size - m) * s[1], (size - m) * s[2]});
        const double rms = std::sqrt(parent.qef.error(parent.position) / parent.qef.count);
        parent.collapsible = rms <= o.tolerance_mm;
        any_collapsed = any_collapsed || parent.collapsible;
      }
      parents.push_back(parent);
      a = b;
    }
    levels.push_back(std::move(parents));
    if (!any_collapsed) break;
  }

  // Top down: every node takes the vertex of its highest collapsed ancestor.
  std::vector<Vec3f> new_positions, new_normals;
  const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  for (size_t level = levels.size() - 1; level >= 1; --level) {
    std::vector<Node>& nodes = levels[level];
    const std::vector<Node>* above = level + 1 < levels.size() ? &levels[level + 1] : nullptr;
    const int64_t size = int64_t{1} << level;
    for (Node& n : nodes) {
      if (above) {
        const auto it = std::lower_bound(above->begin(), above->end(), n.key >> 3,
                                         [](const Node& x, uint64_t key) { return x.key < key; });
        if (it != above->end() && it->key == (n.key >> 3) && it->rep >= 0) {
          n.rep = it->rep;
          continue;
        }
      }
      if (!n.collapsible) continue;
      n.rep = base + static_cast<int64_t>(new_positions.size());
      const auto c3 = unmorton(n.key);
      new_positions.push_back(to_float(grid.to_world({double(c3[0] * size) + n.position.x / s[0],
                                                      double(c3[1] * size) + n.position.y / s[1],
                                                      double(c3[2] * size) + n.position.z / s[2]})));
      const Vec3d wn = grid.direction * n.normal_sum;
      const double len = norm(wn);
      new_normals.push_back(len > 0 ? to_float((1.0 / len) * wn) : Vec3f{0, 0, 1});
    }
    if (level == 1) break;
  }
  if (new_positions.empty()) return mesh;

  // Cells inherit their level-1 parent's vertex.
  std::vector<uint32_t> map(mesh.positions.size());
  for (uint32_t v = 0; v < map.size(); ++v) map[v] = v;
  const std::vector<Node>& level1 = levels[1];
  for (const Node& cell : levels[0]) {
    const auto it = std::lower_bound(level1.begin(), level1.end(), cell.key >> 3,
                                     [](const Node& x, uint64_t key) { return x.key < key; });
    if (it == level1.end() || it->key != (cell.key >> 3) || it->rep < 0) continue;
    map[cell.first_vertex] = static_cast<uint32_t>(it->rep);
  }
  mesh.positions.insert(mesh.positions.end(), new_positions.begin(), new_positions.end());
  mesh.normals.insert(mesh.normals.end(), new_normals.begin(), new_normals.end());

  // Remap the triangles; those that lost a corner to a merge disappear.
  std::vector<uint32_t> indices;
  indices.reserve(mesh.indices.size());
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const uint32_t a = map[mesh.indices[t]], b = map[mesh.indices[t + 1]], c = map[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    indices.insert(indices.end(), {a, b, c});
  }
  // Drop the vertices no triangle uses any more, keeping the order of the rest.
  std::vector<uint32_t> renumber(mesh.positions.size(), UINT32_MAX);
  for (uint32_t v : indices) renumber[v] = 0;
  TriMesh out;
  for (uint32_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] == UINT32_MAX) continue;
    renumber[v] = static_cast<uint32_t>(out.positions.size());
    out.positions.push_back(mesh.positions[v]);
    out.normals.push_back(mesh.normals[v]);
  }
  for (uint32_t& v : indices) v = renumber[v];
  out.indices = std::move(indices);
  return out;
}

}  // namespace segmesh
