#include "segmesh/multi_label_dual_contouring.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <numeric>
#include <optional>
#include <vector>

#include "segmesh/detail/dc_key_table.hpp"
#include "segmesh/detail/dc_material_keys.hpp"
#include "segmesh/detail/dc_neighbourhood_keys.hpp"
#include "segmesh/detail/dc_polygons.hpp"
#include "segmesh/detail/dc_vertices.hpp"
#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/material_faces.hpp"
#include "segmesh/detail/material_rows.hpp"
#include "segmesh/first_touch.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

constexpr int16_t kJunction = -2;

// The edges a cell owns (emits the polygon of): 3, 7 and 11, through its corner (1, 1, 1).
constexpr uint16_t kOwnedEdges = 1u << 3 | 1u << 7 | 1u << 11;

// One thread's solved neighbourhoods: each key's sheet offsets (index space, from the cell's
// first corner). A key decides its cell's case, so its sheet count: a single sheet's offset is the
// table's value (one look-up less for nearly every cell); several sheets' are
// offsets[first .. first + sheets), first the value.
struct SolvedKeys {
  dc::KeyTable<Vec3d> single;
  dc::KeyTable<uint32_t> first;
  std::vector<Vec3d> offsets;
};

// A cell whose corners are not all one material (24 bytes: the scan writes one per cut cell
// and the later passes read them all, so their size is memory traffic).
struct CutCell {
  int32_t i = 0;              // its x
  uint32_t first_vertex = 0;  // slab-local until the slabs are joined
  // A binary cell: the material inside and the other one. A junction cell: `winner` is its
  // index in its slab's junction cells (JunctionCell).
  uint32_t winner = 0, other = 0;
  uint16_t cut = 0;      // its cut edges (bit e: edge e)
  int16_t cs = 0;        // a binary cell: the winner's case; kJunction
  uint8_t vertices = 0;  // its vertices: first_vertex ..
  // A binary cell: bit n set where end n of its owned edges (in JunctionCell::owned_ends' order)
  // holds the winner.
  uint8_t winner_ends = 0;
};
static_assert(sizeof(CutCell) == 24);

// What only a junction cell needs.
struct JunctionCell {
  std::array<int8_t, 12> piece;  // each cut edge's piece (its vertex first_vertex + piece)
  // The materials of the ends of the edges the cell owns (its edges 3, 7 and 11, the ones
  // through its corner (1, 1, 1)): corner (1, 1, 1), then the other end of the x, y and z edge,
  // (0, 1, 1), (1, 0, 1) and (1, 1, 0). From the corners the cell was classified by, so the
  // polygons need no look-up in the voxels.
  std::array<uint32_t, 4> owned_ends;
};

// Classifies a cell from its corners' materials; false when they are all one.
// A junction cell's pieces go to `junction`.
bool classify(const uint32_t* m, bool joined_by_winner, const DcTable& table, CutCell& cell,
              JunctionCell& junction) {
  uint32_t first = m[0], second = m[0];
  bool third = false;
  for (int c = 1; c < 8; ++c) {
    if (m[c] == first) continue;
    if (second == first)
      second = m[c];
    else if (m[c] != second)
      third = true;
  }
  if (second == first) return false;
  uint16_t cut = 0;
  for (int e = 0; e < 12; ++e)
    if (m[kMcEdgeCorner[e][0]] != m[kMcEdgeCorner[e][1]]) cut |= uint16_t(1u << e);
  cell.cut = cut;
  if (!third) {
    cell.winner = winning_material(first, second);
    cell.other = cell.winner == first ? second : first;
    int cs = 0;
    for (int c = 0; c < 8; ++c)
      if (m[c] == cell.winner) cs |= 1 << c;
    cell.cs = int16_t(cs);
    cell.vertices = table.cases[size_t(cs)].piece_count;
    return true;
  }
  // A junction cell: its cut edges (0..11) and face centres (12..17) joined by the face rule.
  std::array<int8_t, 18> parent;
  std::iota(parent.begin(), parent.end(), int8_t{0});
  auto find = [&](int x) {
    while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
    return x;
  };
  FaceSegment s[4];
  for (int f = 0; f < 6; ++f) {
    const int n = face_segments(m, f, joined_by_winner, s);
    for (int q = 0; q < n; ++q) parent[size_t(find(s[q].p))] = int8_t(find(s[q].q));
  }
  std::array<int8_t, 18> piece_of_root;
  piece_of_root.fill(-1);
  cell.cs = kJunction;
  junction.piece.fill(-1);
  int pieces = 0;
  for (int e = 0; e < 12; ++e) {
    if (!(cut >> e & 1)) continue;
    int8_t& p = piece_of_root[size_t(find(e))];
    if (p < 0) p = int8_t(pieces++);
    junction.piece[size_t(e)] = p;
  }
  cell.vertices = uint8_t(pieces);
  return true;
}

// The cut cells of one slab of cells (z = k), by row.
struct Slab {
  std::vector<CutCell> cells;
  std::vector<JunctionCell> junctions;
  std::vector<uint32_t> row_first;  // cells of row j: [row_first[j], row_first[j + 1])
  uint32_t vertices = 0;
  uint32_t junction_vertices = 0;  // the junction cells' vertices among them
  // Per row: the cut edges its cells own, and whether it holds a binary cell of several sheets
  // (a rare cell: only next to one can a polygon be more than a quad).
  std::vector<uint32_t> row_owned;
  std::vector<uint8_t> row_rare;
  uint64_t triangles = 0, extra = 0;  // the polygons' triangles and centroid vertices it emits
};

class Extractor {
 public:
  // `bits`: the parts' inside bits, or null to read keys from the runs (dc_material_keys.hpp).
  Extractor(const MaterialRows& rows, const dc::MaterialBits* bits, const DcOptions& options,
            Progress& progress)
      : rows_(rows),
        bits_(bits),
        grid_(rows.grid()),
        table_(dc_table(options.connectivity)),
        joined_by_winner_(options.connectivity != 6),
        options_{.connectivity = options.connectivity,
                 .svd_eps = options.svd_eps,
                 .vertex_normals = false},
        solve_{grid_, options_, table_, false},
        progress_(progress),
        n_(rows.dims()) {}

  LabelledSurface run() {
    LabelledSurface out;
    if (rows_.empty()) return out;
    slabs_.resize(size_t(n_[2] - 1));
    tbb::parallel_for(int64_t{0}, n_[2] - 1, [&](int64_t k) {
      throw_if_cancelled(progress_);
      scan_slab(k);
    });
    progress_.update(0.3);
    // The polygons' triangles and centroid vertices per slab (their costs need no positions).
    tbb::parallel_for(int64_t{0}, n_[2] - 1, [&](int64_t k) {
      throw_if_cancelled(progress_);
      count_polygons(k);
    });
    // Vertex ids: the slabs' cells in order, then the centroids; the junction vertices likewise.
    std::vector<uint32_t> first_vertex(slabs_.size()), first_junction(slabs_.size());
    std::vector<uint64_t> first_triangle(slabs_.size()), first_extra(slabs_.size());
    uint64_t vertices = 0, junctions = 0, triangles = 0, extra = 0;
    for (size_t k = 0; k < slabs_.size(); ++k) {
      first_vertex[k] = uint32_t(vertices);
      first_junction[k] = uint32_t(junctions);
      vertices += slabs_[k].vertices;
      junctions += slabs_[k].junction_vertices;
      mesh_id_count(vertices, "multi-label dual contouring");
    }
    for (size_t k = 0; k < slabs_.size(); ++k) {
      first_triangle[k] = triangles;
      first_extra[k] = vertices + extra;
      triangles += slabs_[k].triangles;
      extra += slabs_[k].extra;
    }
    mesh_id_count(vertices + extra, "multi-label dual contouring");
    resize_zeroed(out.mesh.positions, size_t(vertices + extra));
    resize_zeroed(out.mesh.indices, size_t(3 * triangles));
    resize_zeroed(out.sides, size_t(triangles));
    out.junction_vertices.resize(size_t(junctions));
    tbb::parallel_for(int64_t{0}, n_[2] - 1, [&](int64_t k) {
      Slab& slab = slabs_[size_t(k)];
      SolvedKeys& solved = solved_.local();  // once per slab: local() is a look-up
      uint32_t* junction = out.junction_vertices.data() + first_junction[size_t(k)];
      for (size_t r = 0; r + 1 < slab.row_first.size(); ++r) {
        if (slab.row_first[r] == slab.row_first[r + 1]) continue;
        const int64_t j = int64_t(r);
        // The rows of the cells' neighbourhoods that keys read, when not from the bits.
        std::array<dc::RowWindow, 12> windows;
        if (!bits_) windows = dc::key_windows(rows_, j, k);
        for (uint32_t c = slab.row_first[r]; c < slab.row_first[r + 1]; ++c) {
          CutCell& cell = slab.cells[c];
          cell.first_vertex += first_vertex[size_t(k)];
          place_vertices(j, k, cell, windows, solved, out.mesh.positions.data());
          if (cell.cs == kJunction)
            for (uint32_t v = 0; v < cell.vertices; ++v) *junction++ = cell.first_vertex + v;
        }
      }
    });
    progress_.update(0.6);
    tbb::parallel_for(int64_t{0}, n_[2] - 1, [&](int64_t k) {
      throw_if_cancelled(progress_);
      write_polygons(k, first_triangle[size_t(k)], uint32_t(first_extra[size_t(k)]), out);
    });
    progress_.update(1.0);
    return out;
  }

 private:
  void scan_slab(int64_t k) {
    Slab& slab = slabs_[size_t(k)];
    // Room for as many cells as the thread's previous slab had, and an eighth more: neighbouring
    // slabs have similar counts, and growing the vector copies every cell.
    size_t& hint = cells_hint_.local();
    slab.cells.reserve(hint + hint / 8);
    slab.row_first.assign(size_t(n_[1]), 0);
    slab.row_owned.assign(size_t(n_[1]), 0);
    slab.row_rare.assign(size_t(n_[1]), 0);
    for (int64_t j = 0; j + 1 < n_[1]; ++j) {
      slab.row_first[size_t(j)] = uint32_t(slab.cells.size());
      uint32_t& owned = slab.row_owned[size_t(j)];
      uint8_t& rare = slab.row_rare[size_t(j)];
      rows_.cells(j, k, [&](int64_t i, const uint32_t* m) {
        CutCell cell;
        JunctionCell junction;
        if (!classify(m, joined_by_winner_, table_, cell, junction)) return;
        owned += uint32_t(std::popcount(unsigned(cell.cut & kOwnedEdges)));
        rare |= uint8_t(cell.cs != kJunction && cell.vertices > 1);
        // MaterialRows::cells numbers corner (x, y, z) as x + 2 y + 4 z.
        const std::array<uint32_t, 4> ends{m[7], m[6], m[5], m[3]};
        if (cell.cs == kJunction) {
          junction.owned_ends = ends;
          cell.winner = uint32_t(slab.junctions.size());
          slab.junctions.push_back(junction);
          slab.junction_vertices += cell.vertices;
        } else {
          for (int n = 0; n < 4; ++n)
            cell.winner_ends |= uint8_t(unsigned(ends[size_t(n)] == cell.winner) << n);
        }
        cell.i = int32_t(i);
        cell.first_vertex = slab.vertices;
        slab.vertices += cell.vertices;
        slab.cells.push_back(cell);
      });
    }
    slab.row_first[size_t(n_[1] - 1)] = uint32_t(slab.cells.size());
    hint = slab.cells.size();
  }

  // The 4 x 4 x 4 neighbourhood of cell (i, j, k) in material w's indicator, as single-label Dual
  // Contouring keys it (dc_neighbourhood_keys.hpp: the cell's corners at 1 and 2), only the points
  // the central differences read (key_mask): the rest cannot change the solve.
  uint64_t indicator_key(uint32_t w, int64_t i, int64_t j, int64_t k,
                         std::array<dc::RowWindow, 12>& windows) const {
    return (bits_ ? bits_->key(w, i, j, k) : dc::window_key(windows, i, w)) & key_mask_;
  }

  // `solved`: the calling thread's solved neighbourhoods.
  void place_vertices(int64_t j, int64_t k, const CutCell& cell,
                      std::array<dc::RowWindow, 12>& windows, SolvedKeys& solved,
                      Vec3f* positions) const {
    const int64_t i = cell.i;
    auto emit = [&](uint32_t v, Vec3d offset) {
      positions[v] = to_float(grid_.to_world(Vec3d{double(i), double(j), double(k)} + offset));
    };
    if (cell.cs != kJunction) {
      // The winner's sheets as single-label Dual Contouring places them.
      // Solved once per neighbourhood and thread (the key decides the case, hence the solve).
      const uint64_t key = indicator_key(cell.winner, i, j, k, windows);  // never 0: it is cut
      if (cell.vertices == 1) {
        emit(cell.first_vertex, solved.single[solved.single.get(key, [&](Vec3d& offset) {
          offset = dc::solve_key(solve_, key, cell.cs, nullptr).offset[0];
        })]);
        return;
      }
      const uint32_t first = solved.first[solved.first.get(key, [&](uint32_t& f) {
        const dc::CellVertices v = dc::solve_key(solve_, key, cell.cs, nullptr);
        f = uint32_t(solved.offsets.size());
        solved.offsets.insert(solved.offsets.end(), v.offset.begin(),
                              v.offset.begin() + cell.vertices);
      })];
      const Vec3d* offset = solved.offsets.data() + first;
      for (int p = 0; p < cell.vertices; ++p) emit(cell.first_vertex + uint32_t(p), offset[p]);
      return;
    }
    // A junction cell: each piece at the mass point of its cut edges' midpoints.
    std::array<Vec3d, 12> sum{};
    std::array<int, 12> count{};
    const std::array<int8_t, 12>& piece = slabs_[size_t(k)].junctions[cell.winner].piece;
    for (int e = 0; e < 12; ++e) {
      if (!(cell.cut >> e & 1)) continue;
      const size_t p = size_t(piece[size_t(e)]);
      sum[p] = sum[p] + cell_point(e);
      ++count[p];
    }
    const Vec3d lo{kDcCellMargin, kDcCellMargin, kDcCellMargin};
    const Vec3d hi{1 - kDcCellMargin, 1 - kDcCellMargin, 1 - kDcCellMargin};
    for (int p = 0; p < cell.vertices; ++p) {
      const Vec3d mass = (1.0 / count[size_t(p)]) * sum[size_t(p)];
      emit(cell.first_vertex + uint32_t(p), keep_in_box(mass, mass, lo, hi));
    }
  }

  // The material at end n of the edges `cell` of slab s owns (JunctionCell::owned_ends).
  static uint32_t owned_end(const Slab& s, const CutCell& cell, int n) {
    if (cell.cs == kJunction) return s.junctions[cell.winner].owned_ends[size_t(n)];
    return cell.winner_ends >> n & 1 ? cell.winner : cell.other;
  }

  // Calls visit(polygon, inside, outside) for each cut edge the cells of row j of slab k own
  // (their edges 3, 7 and 11: the cell is the edge's quadrant (-1, -1)), or quad(vertices, inside,
  // outside) where its four cells hold one vertex each there (the polygon is that quad).
  template <class Quad, class Visit>
  void row_polygons(int64_t j, int64_t k, Quad&& quad, Visit&& visit) const {
    const Slab& s = slabs_[size_t(k)];
    const bool mirrored = grid_.mirrored();
    // The cells of rows j and j + 1 of slabs k and k + 1, which hold every polygon's four cells;
    // row n of these is row j + (n & 1) of slab k + (n >> 1). Each has a cursor at the first cell
    // at or past the current cell's x: the cells a polygon needs are at x or x + 1, so every
    // look-up is at the cursor or one further, and the cursors only move forward.
    struct Cursor {
      const CutCell* at = nullptr;
      const CutCell* end = nullptr;
    };
    auto row_cells = [&](int64_t jj, int64_t kk) {
      Cursor c;
      if (kk >= int64_t(slabs_.size())) return c;
      const Slab& slab = slabs_[size_t(kk)];
      if (jj + 1 >= int64_t(slab.row_first.size())) return c;
      c.at = slab.cells.data() + slab.row_first[size_t(jj)];
      c.end = slab.cells.data() + slab.row_first[size_t(jj) + 1];
      return c;
    };
    const size_t r = size_t(j);
    std::array<Cursor, 4> rows{row_cells(j, k), row_cells(j + 1, k), row_cells(j, k + 1),
                               row_cells(j + 1, k + 1)};
    for (uint32_t ci = s.row_first[r]; ci < s.row_first[r + 1]; ++ci) {
      const CutCell& cell = s.cells[ci];
      if (!(cell.cut & kOwnedEdges)) continue;
      for (Cursor& c : rows)
        while (c.at != c.end && c.at->i < cell.i) ++c.at;
      for (int axis = 0; axis < 3; ++axis) {
        const int e = 4 * axis + 3;
        if (!(cell.cut >> e & 1)) continue;
        // The edge from cell corner (1, 1, 1) minus the axis to corner (1, 1, 1).
        const uint32_t m0 = owned_end(s, cell, 1 + axis);
        const uint32_t m1 = owned_end(s, cell, 0);
        const uint32_t inside = winning_material(m0, m1);
        std::array<dc::CellRef, 4> refs;
        for (int q = 0; q < 4; ++q) {
          const QuadrantCell& at = kQuadrantCells[size_t(axis)][size_t(q)];
          const CutCell* other = rows[size_t(at.row)].at;
          // The cell is cut (the edge is), so it is at the cursor or the next one.
          other += other->i < cell.i + at.dx;
          if (other->cs == kJunction) {
            const Slab& in = slabs_[size_t(k + (at.row >> 1))];
            refs[size_t(q)] = {
                dc::kOneSheet,
                other->first_vertex + uint32_t(in.junctions[other->winner].piece[size_t(at.edge)])};
          } else {
            refs[size_t(q)] = {other->vertices == 1 ? dc::kOneSheet : int(other->cs),
                               other->first_vertex};
          }
        }
        const uint32_t outside = inside == m0 ? m1 : m0;
        if (refs[0].cs == dc::kOneSheet && refs[1].cs == dc::kOneSheet &&
            refs[2].cs == dc::kOneSheet && refs[3].cs == dc::kOneSheet) {
          // Four single vertices: the quad dc::polygon makes of them, without its table.
          const bool reverse = (inside == m0) == mirrored;
          std::array<uint32_t, 4> v;
          for (int q = 0; q < 4; ++q) v[size_t(q)] = refs[size_t(reverse ? 3 - q : q)].first_vertex;
          quad(v, inside, outside);
          continue;
        }
        visit(dc::polygon(table_, axis, refs, inside == m0, mirrored), inside, outside);
      }
    }
  }

  // Where the cell of quadrant q (dc::kQuadrantDu / kQuadrantDv order) around the edge along
  // `axis` that a cell owns lies: in which of the four rows of row_polygons (row j + (row & 1) of
  // slab k + (row >> 1)), at x + dx, and which of its edges the polygon's edge is.
  struct QuadrantCell {
    int row, dx, edge;
  };
  static constexpr std::array<std::array<QuadrantCell, 4>, 3> kQuadrantCells = [] {
    std::array<std::array<QuadrantCell, 4>, 3> out{};
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int q = 0; q < 4; ++q) {
        // The quadrant's cell, offset from the owning cell by 0 or 1 along u and v.
        std::array<int, 3> offset{0, 0, 0};
        offset[size_t(u)] = 1 + dc::kQuadrantDu[q];
        offset[size_t(v)] = 1 + dc::kQuadrantDv[q];
        out[size_t(axis)][size_t(q)] = {
            offset[1] + 2 * offset[2], offset[0],
            dc::local_edge(axis, -dc::kQuadrantDu[q], -dc::kQuadrantDv[q])};
      }
    }
    return out;
  }();

  // Whether a polygon the cells of row j of slab k own can be more than a quad: a rare cell in
  // one of the four rows that hold their cells.
  bool near_rare(int64_t j, int64_t k) const {
    for (int n = 0; n < 4; ++n) {
      const size_t kk = size_t(k + (n >> 1)), jj = size_t(j + (n & 1));
      if (kk < slabs_.size() && jj < slabs_[kk].row_rare.size() && slabs_[kk].row_rare[jj])
        return true;
    }
    return false;
  }

  void count_polygons(int64_t k) {
    Slab& s = slabs_[size_t(k)];
    for (int64_t j = 0; j + 1 < int64_t(s.row_first.size()); ++j) {
      if (s.row_owned[size_t(j)] == 0) continue;
      if (!near_rare(j, k)) {  // only quads: two triangles each
        s.triangles += 2 * uint64_t(s.row_owned[size_t(j)]);
        continue;
      }
      row_polygons(
          j, k, [&](const std::array<uint32_t, 4>&, uint32_t, uint32_t) { s.triangles += 2; },
          [&](const dc::Polygon& p, uint32_t, uint32_t) {
            const auto [t, x] = dc::polygon_cost(p);
            s.triangles += t;
            s.extra += x;
          });
    }
  }

  void write_polygons(int64_t k, uint64_t first_triangle, uint32_t extra, LabelledSurface& out) {
    uint32_t* idx = out.mesh.indices.data() + 3 * first_triangle;
    std::array<uint32_t, 2>* sides = out.sides.data() + first_triangle;
    // Quads wait in a small batch for their diagonals (dc::split_quads, four at a time), so their
    // vertices are split while the positions just read are still in cache.
    constexpr size_t kBatch = 64;
    std::array<dc::PendingQuad, kBatch> quads;
    size_t pending = 0;
    auto add_quad = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
      quads[pending++] = {idx, {a, b, c, d}};
      idx += 6;
      if (pending == kBatch) {
        dc::split_quads(out.mesh.positions.data(), quads.data(), pending);
        pending = 0;
      }
    };
    std::vector<std::array<int, 3>> scratch;
    for (int64_t j = 0; j + 1 < int64_t(slabs_[size_t(k)].row_first.size()); ++j) {
      if (slabs_[size_t(k)].row_owned[size_t(j)] == 0) continue;
      auto quad = [&](const std::array<uint32_t, 4>& v, uint32_t inside, uint32_t outside) {
        sides[0] = {inside, outside};
        sides[1] = {inside, outside};
        sides += 2;
        add_quad(v[0], v[1], v[2], v[3]);
      };
      row_polygons(j, k, quad, [&](const dc::Polygon& p, uint32_t inside, uint32_t outside) {
        const uint64_t t = dc::polygon_cost(p).first;
        for (uint64_t q = 0; q < t; ++q) *sides++ = {inside, outside};
        if (p.n == 4) {
          add_quad(p.vertex[0], p.vertex[1], p.vertex[2], p.vertex[3]);
          return;
        }
        idx = dc::write_polygon(p, out.mesh, extra, idx, scratch);
      });
    }
    dc::split_quads(out.mesh.positions.data(), quads.data(), pending);
  }

  const MaterialRows& rows_;
  const dc::MaterialBits* bits_;
  const Grid& grid_;
  const DcTable& table_;
  const bool joined_by_winner_;
  const DcOptions options_;  // what single-label Dual Contouring of a 0/1 field uses
  const dc::SheetSolve solve_;
  Progress& progress_;
  const std::array<int64_t, 3> n_;
  std::vector<Slab> slabs_;
  const uint64_t key_mask_ = dc::key_mask(NormalMethod::central);
  mutable tbb::enumerable_thread_specific<SolvedKeys> solved_;
  tbb::enumerable_thread_specific<size_t> cells_hint_{size_t{0}};
};

}  // namespace

LabelledSurface multi_label_dual_contouring(const Grid& grid, const Components& components,
                                            std::span<const size_t> parts, const DcOptions& options,
                                            Progress& progress) {
  const MaterialRows rows(grid, components, parts);
  const std::vector<dc::PartBox> boxes = dc::part_boxes(components, parts);
  std::optional<dc::MaterialBits> bits;
  if (!rows.empty() && dc::MaterialBits::fits(boxes, rows.dims())) bits.emplace(rows, boxes);
  LabelledSurface surface = Extractor(rows, bits ? &*bits : nullptr, options, progress).run();
  surface.part_count = parts.size();
  surface.fold_reach = 2;  // labelled_surface.hpp
  return surface;
}

}  // namespace segmesh
