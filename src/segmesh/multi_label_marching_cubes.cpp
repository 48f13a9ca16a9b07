#include "segmesh/multi_label_marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/material_faces.hpp"
#include "segmesh/detail/material_rows.hpp"
#include "segmesh/detail/row_passes.hpp"
#include "segmesh/first_touch.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

// ---- one cell ----------------------------------------------------------------------------------

enum class CellKind : uint8_t { empty, binary, junction };

struct CellClass {
  CellKind kind = CellKind::empty;
  uint16_t cut = 0;  // bit e: edge e joins two materials
  uint8_t binary_case = 0;
  uint8_t centred_faces = 0;  // bit f: face f meets at its centre (junction cells only)
  int triangles = 0;
  uint32_t winner = 0, other = 0;  // binary cells
};

CellClass classify(const uint32_t* m, const McTable& table, bool joined_by_winner) {
  CellClass k;
  uint32_t first = m[0], second = m[0];
  bool third = false;
  for (int c = 1; c < 8; ++c) {
    if (m[c] == first) continue;
    if (second == first) {
      second = m[c];
    } else if (m[c] != second) {
      third = true;
    }
  }
  if (second == first) return k;
  for (int e = 0; e < 12; ++e)
    if (m[kMcEdgeCorner[e][0]] != m[kMcEdgeCorner[e][1]]) k.cut |= uint16_t(1u << e);
  if (!third) {
    k.kind = CellKind::binary;
    k.winner = winning_material(first, second);
    k.other = k.winner == first ? second : first;
    for (int c = 0; c < 8; ++c)
      if (m[c] == k.winner) k.binary_case |= uint8_t(1u << c);
    k.triangles = table.triangle_count(k.binary_case);
    return k;
  }
  k.kind = CellKind::junction;
  FaceSegment s[4];
  for (int f = 0; f < 6; ++f) {
    const int n = face_segments(m, f, joined_by_winner, s);
    k.triangles += n;
    for (int i = 0; i < n; ++i)
      if (s[i].p >= kFacePoint) k.centred_faces |= uint8_t(1u << f);
  }
  return k;
}

// The class of the last cell classified: the cells of a stretch where no row of the four
// changes (a contact or a surface along x) all have the same corners, so each stretch is
// classified once.
class LastCell {
 public:
  const CellClass& classify(const uint32_t* m, const McTable& table, bool joined_by_winner) {
    if (!valid_ || !std::equal(m, m + 8, m_)) {
      std::copy(m, m + 8, m_);
      class_ = segmesh::classify(m, table, joined_by_winner);
      valid_ = true;
    }
    return class_;
  }

 private:
  uint32_t m_[8] = {};
  CellClass class_;
  bool valid_ = false;
};

// ---- the rows ----------------------------------------------------------------------------------

// Vertex kinds of a row, in the order their ids follow (row_passes.hpp): cut x-, y-, z-edges
// starting at the row's grid points, centred faces at x (the face x = i of the cells), at y = j
// and at z = k (the faces at the row's low sides), junction cells' centres.
enum Kind : size_t { kEdgeX, kEdgeY, kEdgeZ, kFaceX, kFaceY, kFaceZ, kCell, kKinds };

class Extractor {
 public:
  Extractor(const MaterialRows& rows, int connectivity, Progress& progress)
      : rows_(rows), table_(mc_table(connectivity)), joined_by_winner_(connectivity != 6),
        progress_(progress), flip_(rows.grid().mirrored()), ny_(rows.dims()[1]),
        nz_(rows.dims()[2]) {}

  LabelledSurface run() {
    LabelledSurface out;
    if (rows_.empty()) return out;
    ids_ = count_rows<kKinds>(ny_, nz_, "multi-label extraction", progress_,
                              [&](int64_t j, int64_t k) { return tally(j, k); });
    resize_zeroed(out.mesh.positions, ids_.vertex_first.back());
    const size_t triangles = ids_.triangle_first.back();
    resize_zeroed(out.mesh.indices, 3 * triangles);
    out.sides.resize(triangles);
    fill_rows(ny_, nz_, progress_, [&](int64_t j, int64_t k, size_t r) {
      emit_row_vertices(j, k, r, out.mesh);
      if (j + 1 < ny_ && k + 1 < nz_ && ids_.counts[r].triangles > 0) emit_cells(j, k, r, out);
    });
    for (size_t r = 0; r < ids_.counts.size(); ++r) {
      const uint32_t first = first_id(ids_, r, kCell);
      for (uint32_t i = 0; i < ids_.counts[r].vertices[kCell]; ++i) {
        out.junction_vertices.push_back(first + i);
      }
    }
    return out;
  }

 private:
  size_t row_index(int64_t j, int64_t k) const { return row_of(ny_, j, k); }
  std::span<const MaterialRun> row(int64_t j, int64_t k) const { return rows_.row(j, k); }

  // Calls visit(i) for each edge along `axis` from grid point (i, j, k) joining two materials.
  template <class Visit>
  void row_edges(int axis, int64_t j, int64_t k, Visit&& visit) const {
    const auto a = row(j, k);
    if (axis == 0) {
      if (a.empty()) return;
      uint32_t last = 0;
      rows_.segments<1>({a}, [&](int64_t s, int64_t, const auto& m) {
        if (s > 0 && m[0] != last) visit(s - 1);
        last = m[0];
      });
      return;
    }
    const auto b = axis == 1 ? row(j + 1, k) : row(j, k + 1);
    if (a.empty() && b.empty()) return;
    rows_.segments<2>({a, b}, [&](int64_t s, int64_t t, const auto& m) {
      if (m[0] != m[1])
        for (int64_t i = s; i < t; ++i) visit(i);
    });
  }

  // The vertices and triangles row (j, k) contributes.
  RowTally<kKinds> tally(int64_t j, int64_t k) const {
    RowTally<kKinds> t;
    row_edges(0, j, k, [&](int64_t) { ++t.vertices[kEdgeX]; });
    if (j + 1 < ny_) row_edges(1, j, k, [&](int64_t) { ++t.vertices[kEdgeY]; });
    if (k + 1 < nz_) row_edges(2, j, k, [&](int64_t) { ++t.vertices[kEdgeZ]; });
    if (j + 1 >= ny_ || k + 1 >= nz_) return t;
    LastCell last;
    rows_.cells(j, k, [&](int64_t, const uint32_t* m) {
      const CellClass& cc = last.classify(m, table_, joined_by_winner_);
      t.triangles += uint64_t(cc.triangles);
      if (cc.kind != CellKind::junction) return;
      ++t.vertices[kCell];
      for (size_t a = 0; a < 3; ++a) t.vertices[kFaceX + a] += cc.centred_faces >> (2 * a) & 1;
    });
    return t;
  }

  Vec3f world(double i, double j, double k) const {
    return to_float(rows_.grid().to_world({i, j, k}));
  }

  void emit_row_vertices(int64_t j, int64_t k, size_t r, TriMesh& mesh) const {
    for (int axis = 0; axis < 3; ++axis) {
      if (ids_.counts[r].vertices[kEdgeX + size_t(axis)] == 0) continue;
      Vec3f* out = mesh.positions.data() + first_id(ids_, r, kEdgeX + size_t(axis));
      row_edges(axis, j, k, [&](int64_t i) {
        *out++ = world(double(i) + (axis == 0 ? 0.5 : 0), double(j) + (axis == 1 ? 0.5 : 0),
                       double(k) + (axis == 2 ? 0.5 : 0));
      });
    }
  }

  void emit_cells(int64_t j, int64_t k, size_t r, LabelledSurface& out) const {
    const size_t first_triangle = ids_.triangle_first[r];
    uint32_t* idx = out.mesh.indices.data() + 3 * first_triangle;
    std::array<uint32_t, 2>* sides = out.sides.data() + first_triangle;
    Vec3f* positions = out.mesh.positions.data();
    // Cursors (row_passes.hpp): the next unvisited cut edge per (row, axis) the cells touch, and
    // the next centred face of each face list the cells read.
    CutEdgeCursors edges = cut_edge_cursors(ids_, j, k);
    uint32_t face_x = first_id(ids_, r, kFaceX), last_face_x = 0;
    uint32_t face_y[2] = {first_id(ids_, r, kFaceY), first_id(ids_, row_index(j + 1, k), kFaceY)};
    uint32_t face_z[2] = {first_id(ids_, r, kFaceZ), first_id(ids_, row_index(j, k + 1), kFaceZ)};
    uint32_t centre = first_id(ids_, r, kCell);
    LastCell last;
    rows_.cells(j, k, [&](int64_t i, const uint32_t* m) {
      const CellClass& cc = last.classify(m, table_, joined_by_winner_);
      if (cc.kind == CellKind::empty) return;
      uint32_t id[19];
      cut_edge_ids(edges, cc.cut, id);
      if (cc.kind == CellKind::binary) {
        const auto* tri = table_.triangles.data() + table_.first[cc.binary_case];
        for (int t = 0; t < cc.triangles; ++t, idx += 3) {
          idx[0] = id[tri[t][0]];
          idx[1] = id[tri[t][flip_ ? 2 : 1]];
          idx[2] = id[tri[t][flip_ ? 1 : 2]];
          *sides++ = {cc.winner, cc.other};
        }
        return;
      }
      // A junction cell: its centred faces' and its own centre's ids, positions of the ones it
      // owns (the faces at its low x, y, z sides, the +x face as the next cell's low x face).
      const double x = double(i), y = double(j), z = double(k);
      const unsigned faces = cc.centred_faces;
      if (faces & 1) id[kFacePoint + 0] = last_face_x;
      if (faces & 2) {
        id[kFacePoint + 1] = last_face_x = face_x++;
        positions[last_face_x] = world(x + 1, y + 0.5, z + 0.5);
      }
      if (faces & 4) {
        id[kFacePoint + 2] = face_y[0]++;
        positions[id[kFacePoint + 2]] = world(x + 0.5, y, z + 0.5);
      }
      if (faces & 8) id[kFacePoint + 3] = face_y[1]++;
      if (faces & 16) {
        id[kFacePoint + 4] = face_z[0]++;
        positions[id[kFacePoint + 4]] = world(x + 0.5, y + 0.5, z);
      }
      if (faces & 32) id[kFacePoint + 5] = face_z[1]++;
      id[kCentre] = centre++;
      positions[id[kCentre]] = world(x + 0.5, y + 0.5, z + 0.5);
      const Vec3d c = cell_point(kCentre);
      FaceSegment s[4];
      for (int f = 0; f < 6; ++f) {
        const int n = face_segments(m, f, joined_by_winner_, s);
        for (int q = 0; q < n; ++q, idx += 3) {
          // The triangle (centre, p, q); its normal points to the outside material.
          const Vec3d normal = cross(cell_point(s[q].p) - c, cell_point(s[q].q) - c);
          const bool towards_a = dot(normal, cell_corner(s[q].corner) - c) > 0;
          idx[0] = id[kCentre];
          idx[1] = id[flip_ ? s[q].q : s[q].p];
          idx[2] = id[flip_ ? s[q].p : s[q].q];
          *sides++ = towards_a ? std::array<uint32_t, 2>{s[q].b, s[q].a}
                               : std::array<uint32_t, 2>{s[q].a, s[q].b};
        }
      }
    });
  }

  const MaterialRows& rows_;
  const McTable& table_;
  const bool joined_by_winner_;
  Progress& progress_;
  const bool flip_;
  const int64_t ny_, nz_;
  RowIds<kKinds> ids_;
};

}  // namespace

LabelledSurface multi_label_marching_cubes(const Grid& grid, const Components& components,
                                           std::span<const size_t> parts, int connectivity,
                                           Progress& progress) {
  const MaterialRows rows(grid, components, parts);
  LabelledSurface surface = Extractor(rows, connectivity, progress).run();
  surface.part_count = parts.size();
  return surface;
}

}  // namespace segmesh
