#include "segmesh/dual_contouring.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <bit>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "segmesh/component_field.hpp"
#include "segmesh/detail/dc_cell_rows.hpp"
#include "segmesh/detail/dc_neighbourhood_cache.hpp"
#include "segmesh/detail/dc_neighbourhood_keys.hpp"
#include "segmesh/detail/dc_polygon_pass.hpp"
#include "segmesh/detail/dc_vertices.hpp"
#include "segmesh/detail/dual_contouring_simplify.hpp"
#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/inside_bits.hpp"
#include "segmesh/first_touch.hpp"

namespace segmesh {

namespace {

using namespace dc;

// Dual Contouring on a field's inside bits (inside_bits.hpp), in the manner of marching_cubes.cpp,
// over the rows of cells of dc_cell_rows.hpp. Passes, each parallel over rows, prefix sums
// between them, the output the same for any thread count:
//   1. per word of cells, the non-trivial and the rare cells; per row, the sheets (count_cells);
//   2. per row, the triangles and centroid vertices of the polygons it owns: two per cut edge
//      (a quad), except next to a rare cell, where the polygon is built and priced
//      (count_polygons);
//   3. the sheet vertices (QEF; emit_vertices below);
//   4. the polygons (emit_polygons).
// `field` is the field itself, or nullptr for a component's bits (its cells are then all at least
// two grid points from the border, and their Hermite data come from their neighbourhood's bits).
template <class T>
class Extractor {
 public:
  Extractor(const Volume<T>* field, const InsideBits& bits, const Grid& grid, bool binary,
            bool zero_one, const DcOptions& options, Progress& progress,
            DcNeighbourhoods* solved = nullptr)
      : f_(field),
        grid_(grid),
        binary_(binary && options.tolerance_mm == 0),
        o_(options),
        solve_{grid, options, dc_table(options.connectivity),
               options.vertex_normals || options.tolerance_mm > 0,
               !zero_one && options.hermite == DcHermite::cubic,
               zero_one ? -kDcCellMargin : options.cell_reach},
        rows_(bits, solve_.table),
        progress_(progress),
        solved_(solved),
        relevant_points_(relevant_points(options.normals)),
        key_mask_(key_mask(options.normals)) {}

  TriMesh run() {
    TriMesh mesh;
    if (rows_.nx < 2 || rows_.ny < 2 || rows_.nz < 2) return mesh;
    count_cells(rows_, progress_);
    count_polygons(rows_, grid_.mirrored(), progress_);
    prefix_sums(rows_);
    resize_zeroed(mesh.positions, rows_.vertices());
    if (solve_.normals) resize_zeroed(mesh.normals, rows_.vertices());
    resize_zeroed(mesh.indices, 3 * size_t{rows_.triangle_first.back()});
    if (o_.tolerance_mm > 0) qefs_.resize(rows_.sheets());
    emit_vertices(mesh);
    emit_polygons(rows_, grid_.mirrored(), mesh, progress_);
    if (o_.tolerance_mm > 0) {
      DcCells cells{{rows_.cx, rows_.cy, rows_.cz},
                    surface_cells(rows_),
                    &qefs_,
                    [this](int64_t i, int64_t j, int64_t k) { return rows_.bits.at(i, j, k); }};
      mesh = simplify_dual_contour(std::move(mesh), cells, grid_, o_);
    }
    return mesh;
  }

 private:
  // Pass 3: the sheet vertices, from the neighbourhood cache where the cell is binary and away
  // from the border, solved alone otherwise. Reports progress from 0 to 0.5.
  void emit_vertices(TriMesh& mesh) {
    std::atomic<int64_t> rows_done{0};
    // The scene's solved neighbourhoods, or this part's own.
    std::optional<DcNeighbourhoods> own;
    DcNeighbourhoods* solved = nullptr;
    if (binary_) {
      solved = solved_ ? solved_ : &own.emplace(grid_, o_);
      if (!solved->tables->fits(grid_, o_)) {
        throw std::logic_error(
            "dual contouring: neighbourhoods solved for another grid or options");
      }
    }
    const InsideBits& bits = rows_.bits;
    const int64_t nx = rows_.nx, ny = rows_.ny, nz = rows_.nz, cy = rows_.cy;
    const bool normals = solve_.normals;
    // A cell's first corner in world space: its row's plus x steps along x.
    const Vec3d step_x = grid_.direction * Vec3d{grid_.spacing[0], 0, 0};
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows_.rows(), 16), [&](const auto& range) {
      throw_if_cancelled(progress_);
      SolvedNeighbourhoods* table = solved ? &solved->tables->threads.local() : nullptr;
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        if (rows_.vertex_first[size_t(r) + 1] == rows_.vertex_first[size_t(r)]) continue;
        const int64_t j = r % cy, k = r / cy;
        const bool rows_inside = j >= 1 && k >= 1 && j + 2 < ny && k + 2 < nz;
        const uint64_t* around[16];
        if (rows_inside) {
          for (int n = 0; n < 16; ++n) around[n] = bits.row(j - 1 + (n & 3), k - 1 + (n >> 2));
        }
        WordColumns columns(around, nx);
        // Keys are made for the cells that may be keyed and will be.
        const bool keys = rows_inside && (table != nullptr || f_ == nullptr);
        const Vec3d row_corner = grid_.to_world({0, double(j), double(k)});
        uint32_t id = rows_.vertex_first[size_t(r)];
        const CellWord* row = rows_.row_words(j, k);
        const CornerRows corner_rows = rows_.corners(j, k);
        for (int64_t w = 0; w < rows_.cw; ++w) {
          if (row[w].cells == 0) continue;
          const CornerWords c = corner_rows.at(w);
          if (keys) columns.load(w, row[w].cells);
          for (uint64_t m = row[w].cells; m != 0; m &= m - 1) {
            const int b = std::countr_zero(m);
            const int64_t x = 64 * w + b;
            // A cell that is not rare holds one sheet; its case is only needed to solve it.
            const auto cs = [&] { return c.case_of(b); };
            const int n = (row[w].rare >> b & 1) ? solve_.pieces(cs()) : 1;
            const bool keyed = rows_inside && x >= 1 && x + 2 < nx;
            if (keyed && table && n <= SheetVertices::kPieces) {  // most cells
              const uint64_t key = neighbourhood_key(columns, b, key_mask_);
              const uint32_t entry = table->by_key.get(key, [&](SheetVertices& out) {
                solve_entry(solve_, relevant_points_, *table, key, cs(), n, out);
              });
              const SheetVertices& v = table->by_key[entry];
              const Vec3d corner = row_corner + double(x) * step_x;
              for (int p = 0; p < n; ++p) {
                const float* o = v.offset[p];
                mesh.positions[id + p] = to_float(corner + Vec3d{o[0], o[1], o[2]});
                if (normals) {
                  const float* nn = table->normals[entry].normal[p];
                  mesh.normals[id + p] = {nn[0], nn[1], nn[2]};
                }
              }
            } else {
              // Solved for this cell alone (not inlined: the loop above stays small).
              auto solve_alone = [&]() __attribute__((noinline)) {
                Qef* qefs = qefs_.empty() ? nullptr : &qefs_[id];
                if (!keyed && f_ == nullptr)
                  throw std::logic_error("dual contouring: a part's cell at its border");
                const int cell_case = cs();
                const CellVertices v =
                    f_ != nullptr
                        ? solve_sheets(solve_, cell_hermite(solve_, *f_, x, j, k, cell_case),
                                       cell_case, qefs)
                        : solve_key(solve_, neighbourhood_key(columns, b, key_mask_), cell_case,
                                    qefs);
                for (int p = 0; p < n; ++p) {
                  const Vec3d d{double(x), double(j), double(k)};
                  mesh.positions[id + p] = to_float(grid_.to_world(d + v.offset[p]));
                  if (normals) mesh.normals[id + p] = world_normal(grid_, v.normal_sum[p]);
                }
              };
              solve_alone();
            }
            id += static_cast<uint32_t>(n);
          }
        }
      }
      progress_.update(0.5 * double(rows_done += range.size()) / double(rows_.rows()));
    });
  }

  const Volume<T>* f_;
  const Grid& grid_;
  const bool binary_;
  const DcOptions& o_;
  const SheetSolve solve_;
  CellRows rows_;
  Progress& progress_;
  DcNeighbourhoods* const solved_;  // the scene's solved neighbourhoods, or nullptr
  const std::array<uint64_t, 256>& relevant_points_;  // per case (relevant_points)
  const uint64_t key_mask_;                           // over all cases (key_mask)
  std::vector<Qef> qefs_;  // per sheet vertex, kept only for the simplification
};

// A field of 0s and 1s contoured between them, in any type: a mask, whose Hermite data are edge
// midpoints (DcHermite applies to grey values only), so a mask meshes the same whatever its type.
template <class T>
bool is_zero_one(const Volume<T>& field, double iso) {
  if (!(iso > 0 && iso < 1)) return false;
  for (T v : field.voxels) {
    if (!(v == T(0) || v == T(1))) return false;
  }
  return true;
}

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
  const InsideBits bits = inside_bits(field, options.iso, progress);
  const bool zero_one = is_zero_one(field, options.iso);
  return Extractor<T>(&field, bits, field.grid, is_binary(field, options.iso), zero_one, options,
                      progress)
      .run();
}

TriMesh dual_contouring(const Grid& grid, const Components& components, const Component& component,
                        const DcOptions& options, Progress& progress, DcNeighbourhoods* solved) {
  DcOptions o = options;
  o.iso = 0.5;
  const InsideBits bits = inside_bits(components, component);
  const Grid part_grid = component_grid(grid, component);
  return Extractor<uint8_t>(nullptr, bits, part_grid, true, true, o, progress, solved).run();
}

template TriMesh dual_contouring(const Volume<uint8_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<int32_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<float>&, const DcOptions&, Progress&);

}  // namespace segmesh
