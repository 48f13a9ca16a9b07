#include "segmesh/dual_contouring.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "segmesh/dual_contouring_table.hpp"
#include "segmesh/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/marching_cubes_table.hpp"
#include "segmesh/qef.hpp"
#include "segmesh/row_trim.hpp"
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



struct Polygon {
  int n = 0;
  std::array<uint32_t, kMaxPolygon> vertex{};
  std::array<int, kMaxPolygon> quadrant{};
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

template <class T>
class Extractor {
 public:
  Extractor(const Volume<T>& field, const DcOptions& options, Progress& progress)
      : f_(field),
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
    classify_cells();
    count();
    const uint64_t vertices = slab_vertex_first_.back() + plane_extra_first_.back();
    if (vertices > std::numeric_limits<uint32_t>::max()) {
      throw Error("dual contouring: the surface has more than 4 billion vertices; "
                  "crop the volume or select fewer labels");
    }
    mesh.positions.resize(vertices);
    mesh.normals.resize(vertices);
    mesh.indices.resize(3 * plane_triangle_first_.back());
    if (o_.tolerance_mm > 0) qefs_.resize(slab_vertex_first_.back());
    emit_vertices(mesh);
    emit_triangles(mesh);
    if (o_.tolerance_mm > 0) {
      DcCells cells{{cx_, cy_, cz_}, surface_cells(), &qefs_,
                    [this](int64_t i, int64_t j, int64_t k) { return inside(i, j, k); }};
      mesh = simplify_dual_contour(std::move(mesh), cells, f_.grid, o_);
    }
    return mesh;
  }

 private:
  bool inside(int64_t i, int64_t j, int64_t k) const { return scan_->inside(i, j, k); }
  size_t cell_row(int64_t j, int64_t k) const { return static_cast<size_t>(k * cy_ + j); }
  // The case of cell (i, j, k): stored only inside each row's trimmed range, 0 elsewhere (no
  // sheets, like 255).
  uint8_t cell_case(int64_t i, int64_t j, int64_t k) const {
    const size_t row = cell_row(j, k);
    const GridRange& r = case_range_[row];
    return i >= r.lo && i < r.hi ? cases_[case_offset_[row] + size_t(i - r.lo)] : uint8_t{0};
  }

  // Cases of the cells that may hold surface (row trimming), stored row by row for the trimmed
  // ranges only: no volume-sized array.
  void classify_cells() {
    scan_.emplace(f_, InsideTest<T>(o_.iso), progress_);
    const size_t rows = static_cast<size_t>(cy_ * cz_);
    case_range_.resize(rows);
    case_offset_.assign(rows + 1, 0);
    for (int64_t k = 0; k < cz_; ++k)
      for (int64_t j = 0; j < cy_; ++j) case_range_[cell_row(j, k)] = scan_->cell_range(j, k);
    for (size_t r = 0; r < rows; ++r) {
      const GridRange& g = case_range_[r];
      case_offset_[r + 1] = case_offset_[r] + (g.empty() ? 0 : size_t(g.hi - g.lo));
    }
    cases_.assign(case_offset_.back(), 0);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, cz_), [&](const auto& r) {
      throw_if_cancelled(progress_);
      for (int64_t k = r.begin(); k < r.end(); ++k)
        for (int64_t j = 0; j < cy_; ++j) {
          const size_t row = cell_row(j, k);
          const int64_t lo = case_range_[row].lo;
          scan_->cells(j, k, [&](int64_t i, int cs) {
            cases_[case_offset_[row] + size_t(i - lo)] = uint8_t(cs);
          });
        }
    });
  }

  // Calls visit(i, DcCase) for the cells of row j of slab k that may hold sheets.
  template <class Visit>
  void for_row_cells(int64_t j, int64_t k, Visit&& visit) const {
    const size_t row = cell_row(j, k);
    const GridRange& range = case_range_[row];
    const uint8_t* cs = cases_.data() + case_offset_[row];
    for (int64_t i = range.lo; i < range.hi; ++i) visit(i, table_.cases[cs[i - range.lo]]);
  }

  // The polygon of the sheets around an edge; n = 0 when a cell around it lies outside the field
  // (the field's outer layer must be background, so such an edge is never cut).
  // `first_vertex(cell index)` gives the first vertex id of a cell.
  template <class FirstVertex>
  Polygon polygon(int axis, int64_t i, int64_t j, int64_t k, FirstVertex&& first_vertex,
                  bool ids_needed = true) const {
    Polygon p;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int64_t cells[3] = {cx_, cy_, cz_};
    for (int q = 0; q < 4; ++q) {
      int64_t c[3] = {i, j, k};
      c[u] += kQuadrantDu[q];
      c[v] += kQuadrantDv[q];
      for (int a = 0; a < 3; ++a) {
        if (c[a] < 0 || c[a] >= cells[a]) return Polygon{};
      }
      const size_t cell = static_cast<size_t>((c[2] * cy_ + c[1]) * cx_ + c[0]);
      const DcCase& dc = table_.cases[cell_case(c[0], c[1], c[2])];
      const int e = local_edge(axis, -kQuadrantDu[q], -kQuadrantDv[q]);
      const int count = dc.around_count[e];
      const uint32_t first = first_vertex(cell, c[2]);
      for (int t = 0; t < count; ++t) {
        const int piece = dc.around[e][kQuadrantForward[q] ? t : count - 1 - t];
        p.vertex[p.n] = first + static_cast<uint32_t>(piece);
        p.quadrant[p.n++] = q;
      }
    }
    if (!ids_needed) return p;  // counting: the size and cells are all that matter
    // Counter-clockwise around +axis faces +axis: right when the inside is at the edge's start.
    // A mirrored grid flips every winding once more.
    if (inside(i, j, k) == f_.grid.mirrored()) {
      std::reverse(p.vertex.begin(), p.vertex.begin() + p.n);
      std::reverse(p.quadrant.begin(), p.quadrant.begin() + p.n);
    }
    return p;
  }

  // Triangles (and centroid vertices, 0 or 1) the polygon of an edge becomes.
  static std::pair<uint64_t, uint64_t> polygon_cost(const Polygon& p) {
    if (p.n == 0) return {0, 0};
    if (p.n == 4) return {2, 0};
    if (triangulable(p)) return {uint64_t(p.n - 2), 0};
    return {uint64_t(p.n), 1};
  }

  void count() {
    std::vector<uint64_t> slab_vertices(cz_, 0), triangles(nz_, 0), extra(nz_, 0), edges(nz_, 0);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_), [&](const auto& r) {
      throw_if_cancelled(progress_);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        if (k < cz_) {
          uint64_t n = 0;
          for (int64_t j = 0; j < cy_; ++j)
            for_row_cells(j, k, [&](int64_t, const DcCase& dc) { n += dc.piece_count; });
          slab_vertices[k] = n;
        }
        // Polygon sizes depend on the cells' cases only; the vertex ids do not matter here.
        uint64_t nt = 0, ne = 0;
        scan_->cut_edges(k, [&](int axis, int64_t i, int64_t j) {
          const auto [t, e] = polygon_cost(polygon(axis, i, j, k, [](size_t, int64_t) { return 0u; },
                                                   /*ids_needed=*/false));
          nt += t;
          ne += e;
          ++edges[k];
        });
        triangles[k] = nt;
        extra[k] = ne;
      }
    });
    slab_vertex_first_.assign(cz_ + 1, 0);
    for (int64_t k = 0; k < cz_; ++k) slab_vertex_first_[k + 1] = slab_vertex_first_[k] + slab_vertices[k];
    plane_triangle_first_.assign(nz_ + 1, 0);
    plane_extra_first_.assign(nz_ + 1, 0);
    edge_first_.assign(nz_ + 1, 0);
    for (int64_t k = 0; k < nz_; ++k) edge_first_[k + 1] = edge_first_[k] + edges[k];
    for (int64_t k = 0; k < nz_; ++k) {
      plane_triangle_first_[k + 1] = plane_triangle_first_[k] + triangles[k];
      plane_extra_first_[k + 1] = plane_extra_first_[k] + extra[k];
    }
  }

  // First vertex id of every cell of slab k that may hold sheets (no other cell is ever looked up).
  void number_slab(int64_t k, std::vector<uint32_t>& first) const {
    if (k < 0 || k >= cz_) return;
    uint32_t id = static_cast<uint32_t>(slab_vertex_first_[k]);
    for (int64_t j = 0; j < cy_; ++j) {
      for_row_cells(j, k, [&](int64_t i, const DcCase& dc) {
        first[j * cx_ + i] = id;
        id += dc.piece_count;
      });
    }
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

  // The QEF vertex of one sheet of cell (i, j, k).
  // The Hermite data of every sign-changing edge, once (a cut edge belongs to up to four cells),
  // in the order TrimmedScan::number_plane gives the edges ids.
  struct Hermite {
    Vec3f point;   // index space
    Vec3f normal;  // unit, outwards, in physical space before the grid's rotation
  };

  void compute_hermite() {
    hermite_.resize(edge_first_.back());
    const auto& s = f_.grid.spacing;
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_), [&](const auto& r) {
      throw_if_cancelled(progress_);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        size_t id = edge_first_[k];
        scan_->cut_edges(k, [&](int axis, int64_t i, int64_t j) {
          const EdgeCrossing c = edge_crossing(f_, i, j, k, axis, o_.iso, o_.normals);
          Vec3d n{-c.index_gradient.x / s[0], -c.index_gradient.y / s[1], -c.index_gradient.z / s[2]};
          double len = norm(n);
          if (!(len > 0)) {  // no gradient: the edge itself, pointing from inside to outside
            n = {double(axis == 0), double(axis == 1), double(axis == 2)};
            if (!inside(i, j, k)) n = -1.0 * n;
            len = 1;
          }
          hermite_[id++] = {to_float(c.index_point), to_float((1.0 / len) * n)};
        });
      }
    });
  }

  // The QEF vertex of one sheet of cell (i, j, k); edge_id(e) gives the id of cell edge e.
  template <class EdgeId>
  void emit_piece(int64_t i, int64_t j, int64_t k, const DcCase& dc, int piece, uint32_t id,
                  EdgeId&& edge_id, TriMesh& mesh) {
    const auto& s = f_.grid.spacing;
    Qef qef;
    Vec3d normal_sum{};
    Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (int t = 0; t < dc.piece_edge_count[piece]; ++t) {
      const Hermite& h = hermite_[edge_id(dc.piece_edges[piece][t])];
      // Physical millimetres relative to the cell's first corner, before the grid's rotation:
      // distances there are true distances, and the numbers stay small.
      const Vec3d p{(h.point.x - double(i)) * s[0], (h.point.y - double(j)) * s[1],
                    (h.point.z - double(k)) * s[2]};
      const Vec3d n = to_double(h.normal);
      qef.add(p, n);
      normal_sum = normal_sum + n;
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    // A cell crossed by several sheets is a configuration of single voxels touching at an edge or
    // corner, where tangent planes say nothing about a feature and the sheets' QEF minima may
    // coincide (the three quads of the tube all meet at the cell centre): each sheet takes its
    // mass point, which keeps the sheets apart.
    const Vec3d target = dc.piece_count > 1 ? qef.mass_point() : solve_qef(qef, o_.svd_eps).position;
    const Vec3d p = keep_in_cell(target, qef.mass_point(), lo, hi, dc.piece_count > 1);
    mesh.positions[id] = to_float(f_.grid.to_world({i + p.x / s[0], j + p.y / s[1], k + p.z / s[2]}));
    const Vec3d wn = f_.grid.direction * normal_sum;
    const double wl = norm(wn);
    mesh.normals[id] = wl > 0 ? to_float((1.0 / wl) * wn) : Vec3f{0, 0, 1};
    if (!qefs_.empty()) qefs_[id] = qef;
  }

  void emit_vertices(TriMesh& mesh) {
    compute_hermite();
    const size_t plane = static_cast<size_t>(nx_ * ny_);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, cz_, 16), [&](const auto& r) {
      throw_if_cancelled(progress_);
      PlaneEdgeIds lo(plane), hi(plane);
      auto no_op = [](int, int64_t, int64_t, uint32_t) {};
      scan_->number_plane(r.begin(), uint32_t(edge_first_[r.begin()]), lo, no_op);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        scan_->number_plane(k + 1, uint32_t(edge_first_[k + 1]), hi, no_op);
        uint32_t id = static_cast<uint32_t>(slab_vertex_first_[k]);
        for (int64_t j = 0; j < cy_; ++j) {
          for_row_cells(j, k, [&](int64_t i, const DcCase& dc) {
            auto edge_id = [&](int e) { return cell_edge_id(lo, hi, e, i, j, nx_); };
            for (int piece = 0; piece < dc.piece_count; ++piece) {
              emit_piece(i, j, k, dc, piece, id++, edge_id, mesh);
            }
          });
        }
        std::swap(lo, hi);
      }
      progress_.update(0.5 * double(r.end()) / double(cz_));
    });
    hermite_ = {};
  }

  void emit_triangles(TriMesh& mesh) {
    const size_t slab = static_cast<size_t>(cx_ * cy_);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_, 4), [&](const auto& r) {
      throw_if_cancelled(progress_);
      std::vector<uint32_t> below(slab), above(slab);  // slabs k - 1 and k
      number_slab(r.begin() - 1, below);
      number_slab(r.begin(), above);
      std::vector<std::array<int, 3>> tris;
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        uint32_t* out = mesh.indices.data() + 3 * plane_triangle_first_[k];
        uint32_t extra = static_cast<uint32_t>(slab_vertex_first_.back() + plane_extra_first_[k]);
        auto first_vertex = [&](size_t cell, int64_t ck) -> uint32_t {
          const size_t in_slab = cell - static_cast<size_t>(ck) * slab;
          return ck == k ? above[in_slab] : below[in_slab];
        };
        scan_->cut_edges(k, [&](int axis, int64_t i, int64_t j) {
          const Polygon p = polygon(axis, i, j, k, first_vertex);
          if (p.n == 0) return;
          auto pos = [&](int a) { return to_double(mesh.positions[p.vertex[a]]); };
          auto rho = [&](int a, int b, int c) { return radii_ratio(pos(a), pos(b), pos(c)); };
          if (p.n == 4) {
            // The diagonal that gives the better pair of triangles (the higher worst radii
            // ratio), from the six edge lengths of the quad.
            const Vec3d v[4] = {pos(0), pos(1), pos(2), pos(3)};
            const double s01 = norm(v[1] - v[0]), s12 = norm(v[2] - v[1]), s23 = norm(v[3] - v[2]),
                         s30 = norm(v[0] - v[3]), d02l = norm(v[2] - v[0]), d13l = norm(v[3] - v[1]);
            const double d02 = std::min(radii_ratio_of_sides(s01, s12, d02l), radii_ratio_of_sides(d02l, s23, s30));
            const double d13 = std::min(radii_ratio_of_sides(s12, s23, d13l), radii_ratio_of_sides(d13l, s30, s01));
            const int s0 = d13 > d02 + 1e-12 ? 1 : 0;
            const int q[4] = {s0, s0 + 1, s0 + 2, (s0 + 3) % 4};
            const uint32_t a = p.vertex[q[0]], b = p.vertex[q[1]], c = p.vertex[q[2]], d = p.vertex[q[3]];
            out[0] = a, out[1] = b, out[2] = c, out[3] = a, out[4] = c, out[5] = d;
            out += 6;
          } else if (triangulate(p, rho, tris)) {
            for (const auto& t : tris) {
              out[0] = p.vertex[t[0]], out[1] = p.vertex[t[1]], out[2] = p.vertex[t[2]];
              out += 3;
            }
          } else {
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
          }
        });
        std::swap(below, above);
        number_slab(k + 1, above);
      }
      progress_.update(0.5 + 0.5 * double(r.end()) / double(nz_));
    });
  }

  // The cells with sheets and their first vertex (for the simplification), in vertex order.
  std::vector<SurfaceCell> surface_cells() const {
    std::vector<SurfaceCell> out;
    for (int64_t k = 0; k < cz_; ++k) {
      uint32_t id = static_cast<uint32_t>(slab_vertex_first_[k]);
      for (int64_t j = 0; j < cy_; ++j) {
        for_row_cells(j, k, [&](int64_t i, const DcCase& dc) {
          if (dc.piece_count == 0) return;
          out.push_back({int32_t(i), int32_t(j), int32_t(k), cell_case(i, j, k), id});
          id += dc.piece_count;
        });
      }
    }
    return out;
  }

  const Volume<T>& f_;
  const DcOptions& o_;
  const DcTable& table_;
  Progress& progress_;
  const int64_t nx_, ny_, nz_, cx_, cy_, cz_;
  std::optional<TrimmedScan<T>> scan_;
  std::vector<GridRange> case_range_;  // per row of cells: the trimmed range
  std::vector<size_t> case_offset_;    // per row of cells: where its cases start in cases_
  std::vector<uint8_t> cases_;
  std::vector<uint64_t> slab_vertex_first_;
  std::vector<uint64_t> plane_triangle_first_;
  std::vector<uint64_t> plane_extra_first_;
  std::vector<Qef> qefs_;  // per sheet vertex, kept only for the simplification
  std::vector<uint64_t> edge_first_;  // first id of each plane's cut edges
  std::vector<Hermite> hermite_;      // per cut edge, while vertices are made
};

}  // namespace

template <class T>
TriMesh dual_contouring(const Volume<T>& field, const DcOptions& options, Progress& progress) {
  return Extractor<T>(field, options, progress).run();
}

template TriMesh dual_contouring(const Volume<uint8_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<int32_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<float>&, const DcOptions&, Progress&);

}  // namespace segmesh
