#include "segmesh/marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "segmesh/component_field.hpp"
#include "segmesh/detail/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/first_touch.hpp"
#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/row_passes.hpp"
#include "segmesh/detail/row_trim.hpp"
#include "segmesh/detail/run_scan.hpp"

namespace segmesh {

namespace {

// Bit e set when cell edge e joins an inside and an outside corner, per case.
constexpr std::array<uint16_t, 256> kCutEdges = [] {
  std::array<uint16_t, 256> m{};
  for (int cs = 0; cs < 256; ++cs) {
    for (int e = 0; e < 12; ++e) {
      if ((cs >> kMcEdgeCorner[e][0] & 1) != (cs >> kMcEdgeCorner[e][1] & 1)) m[cs] |= uint16_t(1u << e);
    }
  }
  return m;
}();

// Marching Cubes over any scan that answers per row (row_trim.hpp's TrimmedScan over a field,
// run_scan.hpp's RunScan over a component's runs): row_edges / row_edge_count, cells / cell_sum.
// `Vertices` places the vertices of one row's cut edges of one axis: emit_row(axis, j, k, id,
// mesh) writes them from id on, in row_edges order.
//
// The passes over rows and the ids are row_passes.hpp's: a row's vertices are its x-edges, then
// its y-edges, then its z-edges, each i ascending, and its triangles are those of the cells
// between it and the rows at y + 1, z + 1.
template <class Scan, class Vertices>
class Extractor {
 public:
  Extractor(const Scan& scan, const std::array<int64_t, 3>& dims, bool mirrored, int connectivity,
            const Vertices& vertices, Progress& progress)
      : scan_(scan), vertices_(vertices), table_(mc_table(connectivity)), progress_(progress),
        flip_(mirrored), ny_(dims[1]), nz_(dims[2]), small_(dims[0] < 2 || ny_ < 2 || nz_ < 2) {}

  TriMesh run(bool normals) {
    TriMesh mesh;
    if (small_) return mesh;
    ids_ = count_rows<3>(ny_, nz_, "marching cubes", progress_, [&](int64_t j, int64_t k) {
      RowTally<3> t;
      t.vertices[0] = uint64_t(scan_.row_edge_count(0, j, k));
      if (j + 1 < ny_) t.vertices[1] = uint64_t(scan_.row_edge_count(1, j, k));
      if (k + 1 < nz_) t.vertices[2] = uint64_t(scan_.row_edge_count(2, j, k));
      if (j + 1 < ny_ && k + 1 < nz_) {
        t.triangles = uint64_t(
            scan_.cell_sum(j, k, [&](int cs) { return int64_t{table_.triangle_count(cs)}; }));
      }
      return t;
    });
    const size_t vertices = ids_.vertex_first.back();
    resize_zeroed(mesh.positions, vertices);
    if (normals) resize_zeroed(mesh.normals, vertices);
    resize_zeroed(mesh.indices, 3 * size_t{ids_.triangle_first.back()});
    fill_rows(ny_, nz_, progress_, [&](int64_t j, int64_t k, size_t r) {
      const RowCount<3>& c = ids_.counts[r];
      for (int axis = 0; axis < 3; ++axis) {
        if (c.vertices[axis] > 0) vertices_.emit_row(axis, j, k, first_id(ids_, r, axis), mesh);
      }
      if (c.triangles > 0) emit_cells(j, k, r, mesh);
    });
    return mesh;
  }

 private:
  void emit_cells(int64_t j, int64_t k, size_t r, TriMesh& mesh) const {
    uint32_t* out = mesh.indices.data() + 3 * size_t{ids_.triangle_first[r]};
    CutEdgeCursors cursors = cut_edge_cursors(ids_, j, k);
    scan_.cells(j, k, [&](int64_t, int cs) {
      uint32_t id[12];
      cut_edge_ids(cursors, kCutEdges[static_cast<size_t>(cs)], id);
      const auto* tri = table_.triangles.data() + table_.first[static_cast<size_t>(cs)];
      const int n = table_.triangle_count(cs);
      for (int t = 0; t < n; ++t, out += 3) {
        out[0] = id[tri[t][0]];
        out[1] = id[tri[t][flip_ ? 2 : 1]];
        out[2] = id[tri[t][flip_ ? 1 : 2]];
      }
    });
  }

  const Scan& scan_;
  const Vertices& vertices_;
  const McTable& table_;
  Progress& progress_;
  const bool flip_;  // a mirrored grid reverses the winding of index space
  const int64_t ny_, nz_;
  const bool small_;  // fewer than two grid points along an axis: no cells
  RowIds<3> ids_;
};

// Vertices of a field: interpolated along the edge, normals from the gradient when asked.
template <class T>
class FieldVertices {
 public:
  FieldVertices(const TrimmedScan<T>& scan, const Volume<T>& field, const McOptions& options)
      : scan_(scan), f_(field), o_(options) {}

  void emit_row(int axis, int64_t j, int64_t k, uint32_t id, TriMesh& mesh) const {
    scan_.row_edges(axis, j, k, [&](int64_t i) { emit(axis, i, j, k, id++, mesh); });
  }

 private:
  void emit(int axis, int64_t i, int64_t j, int64_t k, uint32_t id, TriMesh& mesh) const {
    if (!o_.vertex_normals) {
      mesh.positions[id] = to_float(f_.grid.to_world(edge_point(f_, i, j, k, axis, o_.iso).index_point));
      return;
    }
    const EdgeCrossing c = edge_crossing(f_, i, j, k, axis, o_.iso, o_.normals);
    mesh.positions[id] = to_float(f_.grid.to_world(c.index_point));
    const Vec3d g = f_.grid.gradient_to_world(c.index_gradient);
    const double len = norm(g);
    // Values grow towards the inside, so the outward normal is the negative gradient. A zero
    // gradient (possible in one-voxel-thin binary structures) is repaired from the faces later.
    mesh.normals[id] = len > 0 ? to_float((-1.0 / len) * g) : Vec3f{0, 0, 0};
  }

  const TrimmedScan<T>& scan_;
  const Volume<T>& f_;
  const McOptions& o_;
};

// Vertices of a binary part: every crossing is at the middle of its edge (a 0/1 indicator
// contoured at 0.5), so a vertex is the world point of a half-integer index, computed as a row's
// start plus i steps along x.
class MidpointVertices {
 public:
  explicit MidpointVertices(const RunScan& scan) : scan_(scan) {
    const Grid& g = scan.grid();
    origin_ = {g.origin[0], g.origin[1], g.origin[2]};
    for (int a = 0; a < 3; ++a) {
      Vec3d unit{a == 0 ? g.spacing[0] : 0.0, a == 1 ? g.spacing[1] : 0.0, a == 2 ? g.spacing[2] : 0.0};
      step_[a] = g.direction * unit;
    }
  }

  void emit_row(int axis, int64_t j, int64_t k, uint32_t id, TriMesh& mesh) const {
    const Vec3d start = origin_ + double(j) * step_[1] + double(k) * step_[2] + 0.5 * step_[axis];
    Vec3f* out = mesh.positions.data() + id;
    scan_.row_edges(axis, j, k, [&](int64_t i) { *out++ = to_float(start + double(i) * step_[0]); });
  }

 private:
  const RunScan& scan_;
  Vec3d origin_;
  std::array<Vec3d, 3> step_;  // world offset of one grid step along each axis
};

// Vertices whose gradient vanished take the area-weighted normal of their triangles.
void repair_zero_normals(TriMesh& mesh) {
  std::vector<uint32_t> zero;
  for (uint32_t v = 0; v < mesh.normals.size(); ++v) {
    const Vec3f& n = mesh.normals[v];
    if (n.x == 0 && n.y == 0 && n.z == 0) zero.push_back(v);
  }
  if (zero.empty()) return;
  std::vector<Vec3d> sum(mesh.normals.size());
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    const Vec3d pa = to_double(mesh.positions[a]);
    const Vec3d face = cross(to_double(mesh.positions[b]) - pa, to_double(mesh.positions[c]) - pa);
    for (uint32_t v : {a, b, c}) sum[v] = sum[v] + face;
  }
  for (uint32_t v : zero) {
    const double len = norm(sum[v]);
    mesh.normals[v] = len > 0 ? to_float((1.0 / len) * sum[v]) : Vec3f{0, 0, 1};
  }
}

}  // namespace

template <class T>
TriMesh marching_cubes(const Volume<T>& field, const McOptions& options, Progress& progress) {
  const auto& d = field.grid.dims;
  if (d[0] < 2 || d[1] < 2 || d[2] < 2) return {};
  const TrimmedScan<T> scan(field, InsideTest<T>(options.iso), progress);
  const FieldVertices<T> vertices(scan, field, options);
  TriMesh mesh = Extractor<TrimmedScan<T>, FieldVertices<T>>(scan, d, field.grid.mirrored(),
                                                             options.connectivity, vertices, progress)
                     .run(options.vertex_normals);
  if (options.vertex_normals) repair_zero_normals(mesh);
  return mesh;
}

TriMesh marching_cubes(const Grid& grid, const Components& components, const Component& component,
                       const McOptions& options, Progress& progress) {
  if (options.vertex_normals) {
    McOptions o = options;
    o.iso = 0.5;
    return marching_cubes(component_mask(grid, components, component), o, progress);
  }
  const RunScan scan(grid, components, component);
  const MidpointVertices vertices(scan);
  return Extractor<RunScan, MidpointVertices>(scan, scan.dims(), grid.mirrored(), options.connectivity,
                                              vertices, progress)
      .run(false);
}

template TriMesh marching_cubes(const Volume<uint8_t>&, const McOptions&, Progress&);
template TriMesh marching_cubes(const Volume<int32_t>&, const McOptions&, Progress&);
template TriMesh marching_cubes(const Volume<float>&, const McOptions&, Progress&);

}  // namespace segmesh
