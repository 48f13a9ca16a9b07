#include "segmesh/multi_label_marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <vector>

#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/material_rows.hpp"
#include "segmesh/detail/row_passes.hpp"
#include "segmesh/first_touch.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

// ---- one cell ----------------------------------------------------------------------------------

// Points of a cell: 0..11 the edges' midpoints, 12 + f the centre of face f, 18 the cell's centre.
constexpr int kFacePoint = 12;
constexpr int kCentre = 18;

// Face f = 2 * axis + side; its corners in cyclic order (side: the corners' bit `axis`).
constexpr std::array<std::array<int, 4>, 6> kFaceCorners = [] {
  std::array<std::array<int, 4>, 6> f{};
  for (int a = 0; a < 3; ++a) {
    const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
    const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q) f[2 * a + s][q] = s << a | uv[q][0] << u | uv[q][1] << v;
  }
  return f;
}();

constexpr int edge_of(int c0, int c1) {
  for (int e = 0; e < 12; ++e) {
    if ((kMcEdgeCorner[e][0] == c0 && kMcEdgeCorner[e][1] == c1) ||
        (kMcEdgeCorner[e][0] == c1 && kMcEdgeCorner[e][1] == c0))
      return e;
  }
  return -1;
}

// The cell edge between corners q and q + 1 of face f.
constexpr std::array<std::array<int, 4>, 6> kFaceEdges = [] {
  std::array<std::array<int, 4>, 6> e{};
  for (int f = 0; f < 6; ++f)
    for (int q = 0; q < 4; ++q) e[f][q] = edge_of(kFaceCorners[f][q], kFaceCorners[f][(q + 1) % 4]);
  return e;
}();

Vec3d point_of(int p) {
  if (p < 12) {
    const auto& a = kMcCornerOffset[kMcEdgeCorner[p][0]];
    const auto& b = kMcCornerOffset[kMcEdgeCorner[p][1]];
    return {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
  }
  if (p < kCentre) {
    const int f = p - kFacePoint, axis = f / 2, side = f % 2;
    Vec3d c{0.5, 0.5, 0.5};
    (axis == 0 ? c.x : axis == 1 ? c.y : c.z) = side;
    return c;
  }
  return {0.5, 0.5, 0.5};
}

Vec3d corner_of(int c) {
  const auto& o = kMcCornerOffset[c];
  return {double(o[0]), double(o[1]), double(o[2])};
}

// The material that wins a pair: any part over the background, the earlier part over a later one.
uint32_t winner(uint32_t a, uint32_t b) {
  if (a == 0) return b;
  if (b == 0) return a;
  return std::min(a, b);
}

// A segment of the surface on a cell face, between points p and q, with material `a` on the side
// of corner `corner` and `b` on the other.
struct Segment {
  int8_t p = 0, q = 0, corner = 0;
  uint32_t a = 0, b = 0;
};

// The segments of face f as its corners' materials decide (see the header); joined_by_winner: the
// binary face rule (connectivity 18, 26) joins the winner's diagonal, else the other's.
int face_segments(const uint32_t* m, int f, bool joined_by_winner, Segment* out) {
  const auto& c = kFaceCorners[f];
  const auto& e = kFaceEdges[f];
  const uint32_t q[4] = {m[c[0]], m[c[1]], m[c[2]], m[c[3]]};
  int n = 0;
  // Corner k cut off from the two corners next to it.
  auto cut_off = [&](int k) {
    out[n++] = {int8_t(e[(k + 3) % 4]), int8_t(e[k]), int8_t(c[k]), q[k], q[(k + 1) % 4]};
  };
  const bool diagonal02 = q[0] == q[2] && q[1] != q[0] && q[3] != q[0];
  const bool diagonal13 = q[1] == q[3] && q[0] != q[1] && q[2] != q[1];
  if (diagonal02 && diagonal13) {  // two materials on the diagonals: the binary rule
    const uint32_t w = winner(q[0], q[1]);
    const uint32_t joined = joined_by_winner ? w : (w == q[0] ? q[1] : q[0]);
    for (int k = 0; k < 4; ++k)
      if (q[k] != joined) cut_off(k);
    return n;
  }
  if (diagonal02) {  // the diagonal pair joins; the two others are cut off
    cut_off(1);
    cut_off(3);
    return n;
  }
  if (diagonal13) {
    cut_off(0);
    cut_off(2);
    return n;
  }
  int cut[4], cuts = 0;
  for (int k = 0; k < 4; ++k)
    if (q[k] != q[(k + 1) % 4]) cut[cuts++] = k;  // the edge from corner k to k + 1
  if (cuts == 2) {  // one segment between the two cut edges; corner cut[0] + 1 lies between them
    const int k = (cut[0] + 1) % 4;
    out[n++] = {int8_t(e[cut[0]]), int8_t(e[cut[1]]), int8_t(c[k]), q[k], q[cut[0]]};
    return n;
  }
  // Three or four materials around the face meet at its centre.
  for (int i = 0; i < cuts; ++i) {
    const int k = cut[i];
    out[n++] = {int8_t(kFacePoint + f), int8_t(e[k]), int8_t(c[k]), q[k], q[(k + 1) % 4]};
  }
  return n;
}

bool face_has_centre(const uint32_t* m, int f) {
  Segment s[4];
  const int n = face_segments(m, f, true, s);
  for (int i = 0; i < n; ++i)
    if (s[i].p >= kFacePoint) return true;
  return false;
}

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
    k.winner = winner(first, second);
    k.other = k.winner == first ? second : first;
    for (int c = 0; c < 8; ++c)
      if (m[c] == k.winner) k.binary_case |= uint8_t(1u << c);
    k.triangles = table.triangle_count(k.binary_case);
    return k;
  }
  k.kind = CellKind::junction;
  Segment s[4];
  for (int f = 0; f < 6; ++f) {
    const int n = face_segments(m, f, joined_by_winner, s);
    k.triangles += n;
    for (int i = 0; i < n; ++i)
      if (s[i].p >= kFacePoint) k.centred_faces |= uint8_t(1u << f);
  }
  return k;
}

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

  // Calls visit(i, materials) for every cell of row j of slab k whose corners are not all one
  // material, i ascending (corner numbering of marching_cubes_table.hpp).
  template <class Visit>
  void cells(int64_t j, int64_t k, Visit&& visit) const {
    const std::array<std::span<const MaterialRun>, 4> r{row(j, k), row(j + 1, k), row(j, k + 1),
                                                        row(j + 1, k + 1)};
    if (r[0].empty() && r[1].empty() && r[2].empty() && r[3].empty()) return;
    // Row n holds corners 2n (left face) and 2n + 1 (right face).
    std::array<uint32_t, 4> face{};
    int64_t first = -1;
    uint32_t m[8];
    auto emit = [&](int64_t i, const std::array<uint32_t, 4>& left, const std::array<uint32_t, 4>& right) {
      for (int n = 0; n < 4; ++n) {
        m[2 * n] = left[n];
        m[2 * n + 1] = right[n];
      }
      visit(i, m);
    };
    rows_.segments<4>(r, [&](int64_t s, int64_t, const std::array<uint32_t, 4>& next) {
      if (first >= 0) {
        const bool uniform = face[0] == face[1] && face[1] == face[2] && face[2] == face[3];
        if (!uniform)
          for (int64_t i = first; i < s - 1; ++i) emit(i, face, face);
        emit(s - 1, face, next);  // the cell across the change (may be uniform in the end)
      }
      first = s;
      face = next;
    });
    // The last interval reaches the margin, where every row is background.
  }

  // The vertices and triangles row (j, k) contributes.
  RowTally<kKinds> tally(int64_t j, int64_t k) const {
    RowTally<kKinds> t;
    row_edges(0, j, k, [&](int64_t) { ++t.vertices[kEdgeX]; });
    if (j + 1 < ny_) row_edges(1, j, k, [&](int64_t) { ++t.vertices[kEdgeY]; });
    if (k + 1 < nz_) row_edges(2, j, k, [&](int64_t) { ++t.vertices[kEdgeZ]; });
    if (j + 1 >= ny_ || k + 1 >= nz_) return t;
    cells(j, k, [&](int64_t, const uint32_t* m) {
      const CellClass cc = classify(m, table_, joined_by_winner_);
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
    cells(j, k, [&](int64_t i, const uint32_t* m) {
      const CellClass cc = classify(m, table_, joined_by_winner_);
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
      const Vec3d c = point_of(kCentre);
      Segment s[4];
      for (int f = 0; f < 6; ++f) {
        const int n = face_segments(m, f, joined_by_winner_, s);
        for (int q = 0; q < n; ++q, idx += 3) {
          // The triangle (centre, p, q); its normal points to the outside material.
          const Vec3d normal = cross(point_of(s[q].p) - c, point_of(s[q].q) - c);
          const bool towards_a = dot(normal, corner_of(s[q].corner) - c) > 0;
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
