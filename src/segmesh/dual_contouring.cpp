#include "segmesh/dual_contouring.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "segmesh/component_field.hpp"
#include "segmesh/dual_contouring_table.hpp"
#include "segmesh/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/marching_cubes_table.hpp"
#include "segmesh/qef.hpp"
#include "segmesh/row_trim.hpp"
#include "segmesh/run_scan.hpp"
#include "segmesh/dual_contouring_simplify.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

// The four cells around an edge along axis a, counter-clockwise seen from +a: their offsets along
// u = (a + 1) % 3 and v = (a + 2) % 3 from the edge's grid point, and whether the cell's pieces
// around the edge run from its u-face to its v-face (entering by the u-face) or the reverse.
constexpr int kQuadrantDu[4] = {0, 0, -1, -1};
constexpr int kQuadrantDv[4] = {-1, 0, 0, -1};
constexpr bool kQuadrantForward[4] = {true, false, true, false};

// The cell edge (marching_cubes_table.hpp numbering) along `axis` at cell coordinates (cu, cv)
// along u and v.
int local_edge(int axis, int cu, int cv) {
  return axis * 4 + (axis == 1 ? cv + 2 * cu : cu + 2 * cv);
}

constexpr int kMaxPolygon = 12;



// The first n entries are set (the rest stays uninitialised: one is made per cut edge).
struct Polygon {
  int n = 0;
  std::array<uint32_t, kMaxPolygon> vertex;
  std::array<int, kMaxPolygon> quadrant;
};

// Polygon diagonals may only join sheets of the two cells that share nothing but the edge: any
// other pair may already be joined by an edge of the mesh, and a second one would be non-manifold.
bool diagonal_allowed(const Polygon& p, int i, int j) {
  if ((j - i + p.n) % p.n == 1 || (i - j + p.n) % p.n == 1) return true;
  return (p.quadrant[i] - p.quadrant[j] + 4) % 4 == 2;
}

// Best triangulation under diagonal_allowed by dynamic programming over sub-polygons: the worst
// radii ratio first, then the sum. Returns false when none exists. `rho(i, j, k)` scores a triangle.
template <class Score>
bool triangulate(const Polygon& p, Score&& rho, std::vector<std::array<int, 3>>& out) {
  const int n = p.n;
  struct Best {
    double min = -1, sum = 0;
    int split = -1;
  };
  std::array<std::array<Best, kMaxPolygon>, kMaxPolygon> best{};
  for (int i = 0; i + 1 < n; ++i) best[i][i + 1] = {std::numeric_limits<double>::infinity(), 0, -2};
  for (int len = 2; len < n; ++len) {
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      if (!diagonal_allowed(p, i, j)) continue;
      for (int k = i + 1; k < j; ++k) {
        const Best& a = best[i][k];
        const Best& b = best[k][j];
        if (a.split == -1 || b.split == -1) continue;
        const double r = rho(i, k, j);
        const double mn = std::min({a.min, b.min, r});
        const double sum = a.sum + b.sum + r;
        Best& cur = best[i][j];
        if (cur.split == -1 || mn > cur.min + 1e-12 || (mn > cur.min - 1e-12 && sum > cur.sum + 1e-12)) {
          cur = {mn, sum, k};
        }
      }
    }
  }
  if (best[0][n - 1].split == -1) return false;
  out.clear();
  std::array<std::pair<int, int>, kMaxPolygon> stack;
  int top = 0;
  stack[top++] = {0, n - 1};
  while (top > 0) {
    const auto [i, j] = stack[--top];
    if (j - i < 2) continue;
    const int k = best[i][j].split;
    out.push_back({i, k, j});
    stack[top++] = {i, k};
    stack[top++] = {k, j};
  }
  return true;
}

bool triangulable(const Polygon& p) {
  if (p.n <= 4) return true;
  std::vector<std::array<int, 3>> unused;
  return triangulate(p, [](int, int, int) { return 1.0; }, unused);
}

inline float distance(Vec3f a, Vec3f b) {
  const float x = a.x - b.x, y = a.y - b.y, z = a.z - b.z;
  return std::sqrt(x * x + y * y + z * z);
}

// The radii ratio of a triangle with sides a, b, c, without the sorting of radii_ratio_of_sides
// (quality.hpp): only used to choose between two diagonals, where float and the plain product
// suffice; 0 for degenerate triangles.
inline float sides_ratio(float a, float b, float c) {
  const float f = (b + c - a) * (c + a - b) * (a + b - c);
  const float abc = a * b * c;
  return f > 0 && abc > 0 ? f / abc : 0.0f;
}

// One non-trivial cell in its row's list: x, Marching Cubes case, first sheet vertex.
struct RowCell {
  int32_t x = 0;
  uint8_t cs = 0;
  uint32_t first_vertex = 0;
};

// The Hermite data of a cell's cut edges, relative to the cell: crossing in millimetres from the
// cell's first corner (before the grid's rotation), unit outward normal in the same frame.
struct CellHermite {
  std::array<Vec3d, 12> point;
  std::array<Vec3d, 12> normal;
};

// The sheet vertices of one cell, relative to it: index-space offset from the cell's first corner
// and the world unit normal, per piece. What a binary cell's neighbourhood decides completely.
struct CellVertices {
  std::array<Vec3d, kDcMaxPieces> offset;
  std::array<Vec3f, kDcMaxPieces> normal;
};

// The sheet vertices of a cell with at most two sheets, as NeighbourhoodCache keeps them (plain
// arrays: nothing to initialise for the cells that only read them).
struct SheetVertices {
  static constexpr int kPieces = 2;
  double offset[kPieces][3];
  float normal[kPieces][3];
};

// Sheet vertices of binary cells by their 4 x 4 x 4 neighbourhood (the values every gradient of
// the cell's corners reads, central or Sobel). The QEF of a cell of a 0/1 field is a function of
// its neighbourhood alone, and a surface has few distinct neighbourhoods (about 27 000 among the
// 390 000 surface cells of the phantom, 22 000 among 2.6 million in make_big.py's volume), so each
// is solved once. A fixed-size open-addressing table shared by the tasks: a slot is claimed by
// compare-and-swap of its key and published once its value is written; a task that finds a slot
// still being written, or no free slot in reach, solves the cell itself (and another task may
// store the same key again: the values are equal). The value is what the solve gives, whoever
// computes it, so the output does not depend on the threads. Each task keeps a small direct-mapped
// copy in front of it (NeighbourhoodFront), because neighbouring cells repeat neighbourhoods
// (a wall along x) and the shared table is too large for the caches; one per thread. Cells with more than two
// sheets (rare) are always solved.
class NeighbourhoodCache {
 public:
  explicit NeighbourhoodCache(size_t cells) {
    size_t capacity = 1024;
    while (capacity < 2 * cells && capacity < (size_t{1} << 17)) capacity *= 2;
    slots_ = std::make_unique<Slot[]>(capacity);
    mask_ = capacity - 1;
  }

  static size_t hash(uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<size_t>(k);
  }

  bool find(uint64_t key, SheetVertices& out) const {
    size_t h = hash(key) & mask_;
    for (int probe = 0; probe < kProbes; ++probe, h = (h + 1) & mask_) {
      const Slot& slot = slots_[h];
      const uint64_t k = slot.key.load(std::memory_order_acquire);
      if (k == 0) return false;
      if (k == key && slot.ready.load(std::memory_order_acquire) != 0) {
        out = slot.value;
        return true;
      }
    }
    return false;
  }

  void insert(uint64_t key, const SheetVertices& v) {
    size_t h = hash(key) & mask_;
    for (int probe = 0; probe < kProbes; ++probe, h = (h + 1) & mask_) {
      Slot& slot = slots_[h];
      uint64_t k = slot.key.load(std::memory_order_acquire);
      if (k == key) return;  // stored, or being stored, by another task
      if (k == 0 && slot.key.compare_exchange_strong(k, key, std::memory_order_acq_rel)) {
        slot.value = v;
        slot.ready.store(1, std::memory_order_release);
        return;
      }
    }
  }

 private:
  static constexpr int kProbes = 32;
  struct Slot {
    std::atomic<uint64_t> key{0};  // 0: empty (no non-trivial cell has an empty neighbourhood)
    std::atomic<uint32_t> ready{0};
    SheetVertices value;
  };
  std::unique_ptr<Slot[]> slots_;
  size_t mask_ = 0;
};

// A thread's direct-mapped copy of recently used cache entries.
class NeighbourhoodFront {
 public:
  NeighbourhoodFront() : keys_(kSize, 0), values_(kSize) {}
  // The entry for `key`: from the front, the shared cache, or solve(out) (then stored in both).
  template <class Solve>
  const SheetVertices& get(uint64_t key, NeighbourhoodCache& shared, Solve&& solve) {
    const size_t i = NeighbourhoodCache::hash(key) & (kSize - 1);
    if (keys_[i] != key) {
      if (!shared.find(key, values_[i])) {
        solve(values_[i]);
        shared.insert(key, values_[i]);
      }
      keys_[i] = key;
    }
    return values_[i];
  }

 private:
  static constexpr size_t kSize = 4096;
  std::vector<uint64_t> keys_;
  std::vector<SheetVertices> values_;
};

// Dual Contouring row by row, in the manner of marching_cubes.cpp. Cells live in rows (j, k),
// index k * cy + j; each row's non-trivial cells form a list (x, case, first sheet vertex).
// Vertex ids follow the rows, the cells of a row in x order and the sheets of a cell in order;
// every cut edge's polygon is emitted by the cell that has the edge as its edge 3, 7 or 11 (the
// cell at the edge's lower corner on the two other axes), so the triangles follow the rows too.
// Passes, each parallel over rows: count cells and sheets; fill the lists; sheet vertices (QEF);
// count polygons; emit polygons. Prefix sums between them; the output is the same for any thread
// count.
// The non-trivial cells of a part's mask (margin 2) from the part's runs (run_scan.hpp, margin 1):
// mask cell (i, j, k) is the scan's cell (i - 1, j - 1, k - 1).
struct RunCells {
  const RunScan& scan;
  template <class Visit>
  void cells(int64_t j, int64_t k, Visit&& visit) const {
    if (j < 1 || k < 1) return;
    scan.cells(j - 1, k - 1, [&](int64_t i, int cs) { visit(i + 1, cs); });
  }
};

template <class T, class Cells>
class Extractor {
 public:
  // `cells` lists the non-trivial cells of `field` row by row; `binary`: the field is known to be
  // 0/1 (a part's mask), so the neighbourhood cache may serve it.
  Extractor(const Volume<T>& field, const Cells& cells, bool binary, const DcOptions& options,
            Progress& progress)
      : f_(field),
        cell_source_(cells),
        inside_(options.iso),
        binary_(binary && options.tolerance_mm == 0),
        o_(options),
        table_(dc_table(options.connectivity)),
        progress_(progress),
        nx_(field.grid.dims[0]),
        ny_(field.grid.dims[1]),
        nz_(field.grid.dims[2]),
        cx_(nx_ - 1),
        cy_(ny_ - 1),
        cz_(nz_ - 1) {}

  TriMesh run() {
    TriMesh mesh;
    if (nx_ < 2 || ny_ < 2 || nz_ < 2) return mesh;
    list_cells();
    const uint64_t sheets = vertex_first_.back();
    count_polygons();
    const uint64_t vertices = sheets + extra_first_.back();
    if (vertices > std::numeric_limits<uint32_t>::max()) {
      throw Error("dual contouring: the surface has more than 4 billion vertices; "
                  "crop the volume or select fewer labels");
    }
    mesh.positions.resize(vertices);
    mesh.normals.resize(vertices);
    mesh.indices.resize(3 * triangle_first_.back());
    if (o_.tolerance_mm > 0) qefs_.resize(sheets);
    emit_vertices(mesh);
    emit_polygons(mesh);
    if (o_.tolerance_mm > 0) {
      DcCells cells{{cx_, cy_, cz_}, surface_cells(), &qefs_,
                    [this](int64_t i, int64_t j, int64_t k) { return inside_(f_.at(i, j, k)); }};
      mesh = simplify_dual_contour(std::move(mesh), cells, f_.grid, o_);
    }
    return mesh;
  }

 private:
  int64_t rows() const { return cy_ * cz_; }
  size_t row_index(int64_t j, int64_t k) const { return static_cast<size_t>(k * cy_ + j); }

  // Pass 1 and 2: the non-trivial cells of every row, with their first sheet vertex.
  // Two counts per row, count(j, k, a, b) adding to a and b, in parallel over rows; then their
  // prefix sums into first_a and first_b (rows + 1 entries: where each row's share starts).
  template <class Count>
  void count_rows(std::vector<uint64_t>& first_a, std::vector<uint64_t>& first_b, Count&& count) {
    const size_t n = static_cast<size_t>(rows());
    std::vector<uint64_t> a(n, 0), b(n, 0);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 64), [&](const auto& range) {
      throw_if_cancelled(progress_);
      for (int64_t r = range.begin(); r < range.end(); ++r) count(r % cy_, r / cy_, a[size_t(r)], b[size_t(r)]);
    });
    first_a.assign(n + 1, 0);
    first_b.assign(n + 1, 0);
    for (size_t r = 0; r < n; ++r) {
      first_a[r + 1] = first_a[r] + a[r];
      first_b[r + 1] = first_b[r] + b[r];
    }
  }

  void list_cells() {
    count_rows(cell_first_, vertex_first_, [&](int64_t j, int64_t k, uint64_t& cells, uint64_t& sheets) {
      cell_source_.cells(j, k, [&](int64_t, int cs) {
        ++cells;
        sheets += table_.cases[cs].piece_count;
      });
    });
    cells_.resize(cell_first_.back());
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 64), [&](const auto& range) {
      throw_if_cancelled(progress_);
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        RowCell* out = cells_.data() + cell_first_[size_t(r)];
        uint32_t id = static_cast<uint32_t>(vertex_first_[size_t(r)]);
        cell_source_.cells(r % cy_, r / cy_, [&](int64_t i, int cs) {
          *out++ = {static_cast<int32_t>(i), static_cast<uint8_t>(cs), id};
          id += table_.cases[cs].piece_count;
        });
      }
    });
  }

  const RowCell* row_begin(int64_t j, int64_t k) const {
    return cells_.data() + cell_first_[row_index(j, k)];
  }
  const RowCell* row_end(int64_t j, int64_t k) const {
    return cells_.data() + cell_first_[row_index(j, k) + 1];
  }

  // Keeps a QEF solution x inside its cell, shrunk by kDcCellMargin so that vertices of
  // neighbouring cells never coincide (which would make zero-area triangles). With several sheets
  // in the cell, each stays in the box of its own crossings as far as that box reaches into the
  // cell.
  Vec3d keep_in_cell(Vec3d x, Vec3d m, Vec3d sheet_lo, Vec3d sheet_hi, bool several) const {
    const auto& s = f_.grid.spacing;
    double lo[3], hi[3];
    const double slo[3] = {sheet_lo.x, sheet_lo.y, sheet_lo.z}, shi[3] = {sheet_hi.x, sheet_hi.y, sheet_hi.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = kDcCellMargin * s[a];
      hi[a] = (1 - kDcCellMargin) * s[a];
      if (several) {
        const double l = std::max(lo[a], slo[a]), h = std::min(hi[a], shi[a]);
        if (l <= h) lo[a] = l, hi[a] = h;
      }
    }
    return keep_in_box(x, m, {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
  }

  // The Hermite data of the cut edges of cell (i, j, k) with case cs.
  CellHermite cell_hermite(int64_t i, int64_t j, int64_t k, int cs) const {
    const auto& s = f_.grid.spacing;
    CellHermite h;
    for (int e = 0; e < 12; ++e) {
      const int c0 = kMcEdgeCorner[e][0];
      if ((cs >> c0 & 1) == (cs >> kMcEdgeCorner[e][1] & 1)) continue;
      const int axis = e / 4;
      const int64_t gi = i + (c0 & 1), gj = j + (c0 >> 1 & 1), gk = k + (c0 >> 2);
      const EdgeCrossing c = edge_crossing(f_, gi, gj, gk, axis, o_.iso, o_.normals);
      h.point[e] = {(c.index_point.x - double(i)) * s[0], (c.index_point.y - double(j)) * s[1],
                    (c.index_point.z - double(k)) * s[2]};
      Vec3d n{-c.index_gradient.x / s[0], -c.index_gradient.y / s[1], -c.index_gradient.z / s[2]};
      double len = norm(n);
      if (!(len > 0)) {  // no gradient: the edge itself, pointing from inside to outside
        n = {double(axis == 0), double(axis == 1), double(axis == 2)};
        if (!(cs >> c0 & 1)) n = -1.0 * n;
        len = 1;
      }
      h.normal[e] = (1.0 / len) * n;
    }
    return h;
  }

  // The QEF vertices of every sheet of a cell, relative to the cell; the QEFs into `qefs` when
  // given (simplification).
  CellVertices solve_cell(int64_t i, int64_t j, int64_t k, int cs, Qef* qefs) const {
    const auto& s = f_.grid.spacing;
    const DcCase& dc = table_.cases[cs];
    const CellHermite h = cell_hermite(i, j, k, cs);
    CellVertices out;
    for (int piece = 0; piece < dc.piece_count; ++piece) {
      Qef qef;
      Vec3d normal_sum{};
      Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      for (int t = 0; t < dc.piece_edge_count[piece]; ++t) {
        const int e = dc.piece_edges[piece][t];
        const Vec3d p = h.point[e], n = h.normal[e];
        qef.add(p, n);
        normal_sum = normal_sum + n;
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
      // A cell crossed by several sheets is a configuration of single voxels touching at an edge
      // or corner, where tangent planes say nothing about a feature and the sheets' QEF minima
      // may coincide (the three quads of the tube all meet at the cell centre): each sheet takes
      // its mass point, which keeps the sheets apart.
      const Vec3d target = dc.piece_count > 1 ? qef.mass_point() : solve_qef(qef, o_.svd_eps).position;
      const Vec3d p = keep_in_cell(target, qef.mass_point(), lo, hi, dc.piece_count > 1);
      out.offset[piece] = {p.x / s[0], p.y / s[1], p.z / s[2]};
      const Vec3d wn = f_.grid.direction * normal_sum;
      const double wl = norm(wn);
      out.normal[piece] = wl > 0 ? to_float((1.0 / wl) * wn) : Vec3f{0, 0, 1};
      if (qefs) qefs[piece] = qef;
    }
    return out;
  }

  // The 4 x 4 x 4 grid points around cell (i, j, k) (offsets -1 .. 2), bit (x + 4 y + 16 z) set
  // when inside; coordinates clamped to the field as the gradients clamp them. Never 0 for a
  // non-trivial cell.
  uint64_t neighbourhood(int64_t i, int64_t j, int64_t k) const {
    uint64_t key = 0;
    const bool interior = i >= 1 && j >= 1 && k >= 1 && i + 2 < nx_ && j + 2 < ny_ && k + 2 < nz_;
    for (int z = 0; z < 4; ++z) {
      const int64_t gk = std::clamp<int64_t>(k + z - 1, 0, nz_ - 1);
      for (int y = 0; y < 4; ++y) {
        const int64_t gj = std::clamp<int64_t>(j + y - 1, 0, ny_ - 1);
        const T* row = f_.voxels.data() + static_cast<size_t>((gk * ny_ + gj) * nx_);
        uint64_t bits = 0;
        if (interior) {
          // Four 0/1 bytes to four bits: the multiply moves byte b's bit to bit 21 + b.
          uint32_t w;
          std::memcpy(&w, row + i - 1, 4);
          bits = (uint64_t{w} * 0x204081u) >> 21 & 0xf;
        } else {
          for (int x = 0; x < 4; ++x) {
            bits |= uint64_t(row[std::clamp<int64_t>(i + x - 1, 0, nx_ - 1)] != 0) << x;
          }
        }
        key |= bits << (4 * y + 16 * z);
      }
    }
    return key;
  }

  // Pass 3: the sheet vertices.
  void emit_vertices(TriMesh& mesh) {
    std::atomic<int64_t> rows_done{0};
    std::optional<NeighbourhoodCache> cache;
    if (binary_) cache.emplace(cells_.size());
    tbb::enumerable_thread_specific<NeighbourhoodFront> fronts;  // made on first use per thread
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 16), [&](const auto& range) {
      throw_if_cancelled(progress_);
      NeighbourhoodFront* front = cache ? &fronts.local() : nullptr;
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        const int64_t j = r % cy_, k = r / cy_;
        for (const RowCell* c = row_begin(j, k); c != row_end(j, k); ++c) {
          const int pieces = table_.cases[c->cs].piece_count;
          if (pieces == 0) continue;
          auto emit = [&](int piece, const double* d, Vec3f normal) {
            mesh.positions[c->first_vertex + piece] =
                to_float(f_.grid.to_world({double(c->x) + d[0], double(j) + d[1], double(k) + d[2]}));
            mesh.normals[c->first_vertex + piece] = normal;
          };
          if (cache && pieces <= SheetVertices::kPieces) {
            const SheetVertices& v = front->get(neighbourhood(c->x, j, k), *cache, [&](SheetVertices& out) {
              const CellVertices full = solve_cell(c->x, j, k, c->cs, nullptr);
              for (int p = 0; p < pieces; ++p) {
                out.offset[p][0] = full.offset[p].x, out.offset[p][1] = full.offset[p].y;
                out.offset[p][2] = full.offset[p].z;
                out.normal[p][0] = full.normal[p].x, out.normal[p][1] = full.normal[p].y;
                out.normal[p][2] = full.normal[p].z;
              }
            });
            for (int p = 0; p < pieces; ++p) {
              emit(p, v.offset[p], {v.normal[p][0], v.normal[p][1], v.normal[p][2]});
            }
          } else {
            const CellVertices full =
                solve_cell(c->x, j, k, c->cs, qefs_.empty() ? nullptr : &qefs_[c->first_vertex]);
            for (int p = 0; p < pieces; ++p) {
              const double d[3] = {full.offset[p].x, full.offset[p].y, full.offset[p].z};
              emit(p, d, full.normal[p]);
            }
          }
        }
      }
      progress_.update(0.5 * double(rows_done += range.size()) / double(rows()));
    });
  }

  static const RowCell* right_neighbour(const RowCell* c, const RowCell* end) {
    return c != nullptr && c + 1 != end && c[1].x == c->x + 1 ? c + 1 : nullptr;
  }

  // The cells at x and x + 1 of one row's list, found by a cursor that only moves forwards.
  class RowCursor {
   public:
    RowCursor(const RowCell* begin, const RowCell* end) : at_(begin), end_(end) {}
    // The cell at x (x never decreases between calls), or nullptr.
    const RowCell* at(int64_t x) {
      while (at_ != end_ && at_->x < x) ++at_;
      return at_ != end_ && at_->x == x ? at_ : nullptr;
    }
    // The cell after c in the row when it is its neighbour at c->x + 1, or nullptr (also for
    // c == nullptr: an edge that needs both is then not cut, and polygon() reports it).
    const RowCell* right_of(const RowCell* c) const { return right_neighbour(c, end_); }

   private:
    const RowCell* at_;
    const RowCell* end_;
  };

  // Calls visit(axis, quadrant cells, inside at the edge's start) for every cut edge the cells of
  // row (j, k) own: edge 3 (along x), 7 (along y) and 11 (along z) of each cell. The quadrant
  // cells are the four cells around the edge in polygon() order (kQuadrantDu / kQuadrantDv).
  template <class Visit>
  void owned_edges(int64_t j, int64_t k, Visit&& visit) const {
    const bool up = j + 1 < cy_, far = k + 1 < cz_;
    RowCursor r10(up ? row_begin(j + 1, k) : nullptr, up ? row_end(j + 1, k) : nullptr);
    RowCursor r01(far ? row_begin(j, k + 1) : nullptr, far ? row_end(j, k + 1) : nullptr);
    RowCursor r11(up && far ? row_begin(j + 1, k + 1) : nullptr, up && far ? row_end(j + 1, k + 1) : nullptr);
    const RowCell* end = row_end(j, k);
    for (const RowCell* c = row_begin(j, k); c != end; ++c) {
      const int cs = c->cs;
      const int64_t x = c->x;
      const bool cut3 = (cs >> 6 & 1) != (cs >> 7 & 1);   // corners 6, 7
      const bool cut7 = (cs >> 5 & 1) != (cs >> 7 & 1);   // corners 5, 7
      const bool cut11 = (cs >> 3 & 1) != (cs >> 7 & 1);  // corners 3, 7
      if (!cut3 && !cut7 && !cut11) continue;
      const RowCell* a10 = r10.at(x);
      const RowCell* a01 = r01.at(x);
      const RowCell* a11 = r11.at(x);
      const RowCell* right = right_neighbour(c, end);
      if (cut3) visit(0, std::array<const RowCell*, 4>{a10, a11, a01, c}, (cs >> 6 & 1) != 0);
      if (cut7) {
        visit(1, std::array<const RowCell*, 4>{a01, r01.right_of(a01), right, c},
              (cs >> 5 & 1) != 0);
      }
      if (cut11) {
        visit(2, std::array<const RowCell*, 4>{right, r10.right_of(a10), a10, c},
              (cs >> 3 & 1) != 0);
      }
    }
  }

  // Quadrant q's cell around a cut edge: it exists, as every cell around a cut edge is
  // non-trivial.
  static const RowCell& quadrant_cell(const std::array<const RowCell*, 4>& quadrant, int q) {
    if (quadrant[q] == nullptr) throw std::logic_error("dual contouring: a cut edge without its four cells");
    return *quadrant[q];
  }

  // The number of sheets around an edge along `axis`: its polygon's size.
  int polygon_size(int axis, const std::array<const RowCell*, 4>& quadrant) const {
    int size = 0;
    for (int q = 0; q < 4; ++q) {
      size += table_.cases[quadrant_cell(quadrant, q).cs].around_count[local_edge(axis, -kQuadrantDu[q], -kQuadrantDv[q])];
    }
    return size;
  }

  // The polygon of the sheets around an edge along `axis` from its four cells (all non-trivial,
  // as every cell around a cut edge is), wound counter-clockwise seen from outside.
  Polygon polygon(int axis, const std::array<const RowCell*, 4>& quadrant, bool inside_at_start) const {
    Polygon p;
    for (int q = 0; q < 4; ++q) {
      const RowCell* cell = &quadrant_cell(quadrant, q);
      const DcCase& dc = table_.cases[cell->cs];
      const int e = local_edge(axis, -kQuadrantDu[q], -kQuadrantDv[q]);
      const int count = dc.around_count[e];
      for (int t = 0; t < count; ++t) {
        const int piece = dc.around[e][kQuadrantForward[q] ? t : count - 1 - t];
        p.vertex[p.n] = cell->first_vertex + static_cast<uint32_t>(piece);
        p.quadrant[p.n++] = q;
      }
    }
    // Counter-clockwise around +axis faces +axis: right when the inside is at the edge's start.
    // A mirrored grid flips every winding once more.
    if (inside_at_start == f_.grid.mirrored()) {
      std::reverse(p.vertex.begin(), p.vertex.begin() + p.n);
      std::reverse(p.quadrant.begin(), p.quadrant.begin() + p.n);
    }
    return p;
  }

  // Triangles (and centroid vertices, 0 or 1) the polygon of an edge becomes.
  static std::pair<uint64_t, uint64_t> polygon_cost(const Polygon& p) {
    if (p.n == 4) return {2, 0};
    if (triangulable(p)) return {uint64_t(p.n - 2), 0};
    return {uint64_t(p.n), 1};
  }

  // Pass 4: triangles and centroid vertices per row.
  void count_polygons() {
    count_rows(triangle_first_, extra_first_, [&](int64_t j, int64_t k, uint64_t& triangles, uint64_t& extra) {
      owned_edges(j, k, [&](int axis, const auto& quadrant, bool in) {
        if (polygon_size(axis, quadrant) == 4) {  // nearly every edge: a quad, two triangles
          triangles += 2;
          return;
        }
        const auto [t, e] = polygon_cost(polygon(axis, quadrant, in));
        triangles += t;
        extra += e;
      });
    });
  }

  // Pass 5: the polygons, split into triangles.
  void emit_polygons(TriMesh& mesh) {
    std::atomic<int64_t> rows_done{0};
    const uint64_t sheets = vertex_first_.back();
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 64), [&](const auto& range) {
      throw_if_cancelled(progress_);
      std::vector<std::array<int, 3>> tris;
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        uint32_t* out = mesh.indices.data() + 3 * triangle_first_[size_t(r)];
        uint32_t extra = static_cast<uint32_t>(sheets + extra_first_[size_t(r)]);
        owned_edges(r % cy_, r / cy_, [&](int axis, const auto& quadrant, bool in) {
          const Polygon p = polygon(axis, quadrant, in);
          auto pos = [&](int a) { return to_double(mesh.positions[p.vertex[a]]); };
          if (p.n == 4) {
            // The diagonal that gives the better pair of triangles (the higher worst radii
            // ratio), from the six edge lengths of the quad.
            const Vec3f* v = mesh.positions.data();
            const uint32_t* q4 = p.vertex.data();
            const float s01 = distance(v[q4[0]], v[q4[1]]), s12 = distance(v[q4[1]], v[q4[2]]),
                        s23 = distance(v[q4[2]], v[q4[3]]), s30 = distance(v[q4[3]], v[q4[0]]),
                        d02l = distance(v[q4[0]], v[q4[2]]), d13l = distance(v[q4[1]], v[q4[3]]);
            const float d02 = std::min(sides_ratio(s01, s12, d02l), sides_ratio(d02l, s23, s30));
            const float d13 = std::min(sides_ratio(s12, s23, d13l), sides_ratio(d13l, s30, s01));
            const int s0 = d13 > d02 + 1e-6f ? 1 : 0;
            const int q[4] = {s0, s0 + 1, s0 + 2, (s0 + 3) % 4};
            const uint32_t a = p.vertex[q[0]], b = p.vertex[q[1]], c = p.vertex[q[2]], d = p.vertex[q[3]];
            out[0] = a, out[1] = b, out[2] = c, out[3] = a, out[4] = c, out[5] = d;
            out += 6;
            return;
          }
          auto rho = [&](int a, int b, int c) { return radii_ratio(pos(a), pos(b), pos(c)); };
          if (triangulate(p, rho, tris)) {
            for (const auto& t : tris) {
              out[0] = p.vertex[t[0]], out[1] = p.vertex[t[1]], out[2] = p.vertex[t[2]];
              out += 3;
            }
            return;
          }
          // No manifold-safe diagonals: a fan around a new vertex at the polygon's centroid.
          Vec3d centre{}, normal{};
          for (int a = 0; a < p.n; ++a) {
            centre = centre + pos(a);
            normal = normal + to_double(mesh.normals[p.vertex[a]]);
          }
          mesh.positions[extra] = to_float((1.0 / p.n) * centre);
          const double nl = norm(normal);
          mesh.normals[extra] = nl > 0 ? to_float((1.0 / nl) * normal) : Vec3f{0, 0, 1};
          for (int a = 0; a < p.n; ++a) {
            out[0] = extra, out[1] = p.vertex[a], out[2] = p.vertex[(a + 1) % p.n];
            out += 3;
          }
          ++extra;
        });
      }
      progress_.update(0.5 + 0.5 * double(rows_done += range.size()) / double(rows()));
    });
  }

  // The cells with sheets and their first vertex (for the simplification), in vertex order.
  std::vector<SurfaceCell> surface_cells() const {
    std::vector<SurfaceCell> out;
    for (int64_t r = 0; r < rows(); ++r) {
      const int64_t j = r % cy_, k = r / cy_;
      for (const RowCell* c = row_begin(j, k); c != row_end(j, k); ++c) {
        if (table_.cases[c->cs].piece_count == 0) continue;
        out.push_back({c->x, int32_t(j), int32_t(k), c->cs, c->first_vertex});
      }
    }
    return out;
  }

  const Volume<T>& f_;
  const Cells& cell_source_;
  const InsideTest<T> inside_;
  const bool binary_;
  const DcOptions& o_;
  const DcTable& table_;
  Progress& progress_;
  const int64_t nx_, ny_, nz_, cx_, cy_, cz_;
  std::vector<RowCell> cells_;            // every row's non-trivial cells
  std::vector<uint64_t> cell_first_;      // per row: its first entry in cells_
  std::vector<uint64_t> vertex_first_;    // per row: its first sheet vertex
  std::vector<uint64_t> triangle_first_;  // per row: its first triangle
  std::vector<uint64_t> extra_first_;     // per row: its first centroid vertex (after the sheets)
  std::vector<Qef> qefs_;  // per sheet vertex, kept only for the simplification
};

// A 0/1 field contoured between 0 and 1, whose cells the neighbourhood cache may serve.
template <class T>
bool is_binary(const Volume<T>& field, double iso) {
  if constexpr (!std::is_same_v<T, uint8_t>) {
    return false;
  } else {
    if (!(iso > 0 && iso < 1)) return false;
    uint8_t any_above = 0;
    for (uint8_t v : field.voxels) any_above |= v & 0xfe;
    return any_above == 0;
  }
}

}  // namespace

template <class T>
TriMesh dual_contouring(const Volume<T>& field, const DcOptions& options, Progress& progress) {
  const auto& d = field.grid.dims;
  if (d[0] < 2 || d[1] < 2 || d[2] < 2) return {};
  const TrimmedScan<T> scan(field, InsideTest<T>(options.iso), progress);
  return Extractor<T, TrimmedScan<T>>(field, scan, is_binary(field, options.iso), options, progress).run();
}

TriMesh dual_contouring(const Grid& grid, const Components& components, const Component& component,
                        const DcOptions& options, Progress& progress) {
  DcOptions o = options;
  o.iso = 0.5;
  const Volume<uint8_t> mask = component_mask(grid, components, component);
  const RunScan scan(grid, components, component);
  const RunCells cells{scan};
  return Extractor<uint8_t, RunCells>(mask, cells, true, o, progress).run();
}

template TriMesh dual_contouring(const Volume<uint8_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<int32_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<float>&, const DcOptions&, Progress&);

}  // namespace segmesh
