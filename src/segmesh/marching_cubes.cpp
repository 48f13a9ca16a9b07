#include "segmesh/marching_cubes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "segmesh/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/marching_cubes_table.hpp"
#include "segmesh/row_trim.hpp"

namespace segmesh {

namespace {

// Vertex ids of the cut edges that start at the grid points of one z-plane. Left uninitialised:
// only entries of cut edges are ever written and read.
struct PlaneIds {
  std::unique_ptr<uint32_t[]> x, y, z;
  explicit PlaneIds(size_t n)
      : x(new uint32_t[n]), y(new uint32_t[n]), z(new uint32_t[n]) {}
};

template <class T>
class Extractor {
 public:
  Extractor(const Volume<T>& field, const McOptions& options, Progress& progress)
      : f_(field),
        o_(options),
        table_(mc_table(options.connectivity)),
        progress_(progress),
        inside_(options.iso),
        nx_(field.grid.dims[0]),
        ny_(field.grid.dims[1]),
        nz_(field.grid.dims[2]) {}

  TriMesh run() {
    TriMesh mesh;
    if (nx_ < 2 || ny_ < 2 || nz_ < 2) return mesh;
    rows_ = trim_rows(f_, inside_, progress_);
    count();
    const uint64_t vertices = vertex_first_.back();
    if (vertices > std::numeric_limits<uint32_t>::max()) {
      throw Error("marching cubes: the surface has more than 4 billion vertices; "
                  "crop the volume or select fewer labels");
    }
    mesh.positions.resize(vertices);
    mesh.normals.resize(vertices);
    mesh.indices.resize(3 * triangle_first_.back());
    fill(mesh);
    repair_zero_normals(mesh);
    return mesh;
  }

 private:
  const T* row(int64_t j, int64_t k) const {
    return f_.voxels.data() + static_cast<size_t>((k * ny_ + j) * nx_);
  }
  const RowTrim& trim(int64_t j, int64_t k) const { return rows_[static_cast<size_t>(k * ny_ + j)]; }

  // Calls visit(axis, i, j) for every cut edge starting in plane k, in vertex-id order (row by
  // row, x ascending, x- then y- then z-edge), looking only where the trimmed rows say an edge
  // can be cut.
  template <class Visit>
  void for_cut_edges(int64_t k, Visit&& visit) const {
    for (int64_t j = 0; j < ny_; ++j) {
      const RowTrim& r = trim(j, k);
      const bool has_y = j + 1 < ny_, has_z = k + 1 < nz_;
      GridRange range = r.cut_range();
      if (has_y) range = range.merge(pair_range(r, trim(j + 1, k), nx_));
      if (has_z) range = range.merge(pair_range(r, trim(j, k + 1), nx_));
      if (range.empty()) continue;
      const T* a = row(j, k);
      const T* ay = has_y ? row(j + 1, k) : nullptr;
      const T* az = has_z ? row(j, k + 1) : nullptr;
      for (int64_t i = range.lo; i < range.hi; ++i) {
        const bool in = inside_(a[i]);
        if (i + 1 < nx_ && inside_(a[i + 1]) != in) visit(0, i, j);
        if (has_y && inside_(ay[i]) != in) visit(1, i, j);
        if (has_z && inside_(az[i]) != in) visit(2, i, j);
      }
    }
  }

  // Calls visit(i, case) for every non-trivial cell of slab k (cells between planes k, k + 1) in
  // row j, x ascending. The case is built by sliding along x: the right face of one cell is the
  // left face of the next.
  template <class Visit>
  void for_cells(int64_t j, int64_t k, Visit&& visit) const {
    const GridRange range = quad_range(trim(j, k), trim(j + 1, k), trim(j, k + 1), trim(j + 1, k + 1), nx_);
    if (range.empty()) return;
    const T* r00 = row(j, k);
    const T* r10 = row(j + 1, k);
    const T* r01 = row(j, k + 1);
    const T* r11 = row(j + 1, k + 1);
    const int64_t first = std::max<int64_t>(range.lo - 1, 0);
    const int64_t last = std::min<int64_t>(range.hi, nx_ - 1);  // cells [first, last)
    auto face = [&](int64_t x) {  // bits of corners 0, 2, 4, 6 of the cell starting at x
      return int(inside_(r00[x])) | int(inside_(r10[x])) << 2 | int(inside_(r01[x])) << 4 |
             int(inside_(r11[x])) << 6;
    };
    int left = face(first);
    for (int64_t i = first; i < last; ++i) {
      const int right = face(i + 1);
      const int cs = left | right << 1;
      left = right;
      if (cs != 0 && cs != 255) visit(i, cs);
    }
  }

  void count() {
    std::vector<uint64_t> vertices(nz_), triangles(nz_);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_), [&](const auto& r) {
      throw_if_cancelled(progress_);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        uint64_t nv = 0;
        for_cut_edges(k, [&](int, int64_t, int64_t) { ++nv; });
        vertices[k] = nv;
        uint64_t nt = 0;
        if (k + 1 < nz_) {
          for (int64_t j = 0; j + 1 < ny_; ++j) {
            for_cells(j, k, [&](int64_t, int cs) { nt += table_.triangle_count(cs); });
          }
        }
        triangles[k] = nt;
      }
    });
    vertex_first_.assign(nz_ + 1, 0);
    triangle_first_.assign(nz_ + 1, 0);
    for (int64_t k = 0; k < nz_; ++k) {
      vertex_first_[k + 1] = vertex_first_[k] + vertices[k];
      triangle_first_[k + 1] = triangle_first_[k] + triangles[k];
    }
  }

  // Assigns ids to the cut edges of plane k; with `emit`, also computes their vertices.
  void number_plane(int64_t k, bool emit, PlaneIds& ids, TriMesh& mesh) const {
    uint32_t id = static_cast<uint32_t>(vertex_first_[k]);
    for_cut_edges(k, [&](int axis, int64_t i, int64_t j) {
      const size_t at = static_cast<size_t>(j * nx_ + i);
      (axis == 0 ? ids.x : axis == 1 ? ids.y : ids.z)[at] = id;
      if (emit) emit_vertex(axis, i, j, k, id, mesh);
      ++id;
    });
  }

  void emit_vertex(int axis, int64_t i, int64_t j, int64_t k, uint32_t id, TriMesh& mesh) const {
    const EdgeCrossing c = edge_crossing(f_, i, j, k, axis, o_.iso, o_.normals);
    mesh.positions[id] = to_float(f_.grid.to_world(c.index_point));
    const Vec3d g = f_.grid.gradient_to_world(c.index_gradient);
    const double len = norm(g);
    // Values grow towards the inside, so the outward normal is the negative gradient. A zero
    // gradient (possible in one-voxel-thin binary structures) is repaired from the faces later.
    mesh.normals[id] = len > 0 ? to_float((-1.0 / len) * g) : Vec3f{0, 0, 0};
  }

  void emit_triangles(int64_t k, const PlaneIds& lo, const PlaneIds& hi, TriMesh& mesh) const {
    uint32_t* out = mesh.indices.data() + 3 * triangle_first_[k];
    const bool flip = f_.grid.mirrored();
    for (int64_t j = 0; j + 1 < ny_; ++j) {
      for_cells(j, k, [&](int64_t i, int cs) {
        auto edge_id = [&](int e) -> uint32_t {
          const int b = e & 3;
          const int lo_bit = b & 1, hi_bit = b >> 1;
          switch (e >> 2) {
            case 0: return (hi_bit ? hi : lo).x[(j + lo_bit) * nx_ + i];
            case 1: return (hi_bit ? hi : lo).y[j * nx_ + i + lo_bit];
            default: return lo.z[(j + hi_bit) * nx_ + i + lo_bit];
          }
        };
        const int n = table_.triangle_count(cs);
        for (int t = 0; t < n; ++t) {
          const auto& tri = table_.triangles[table_.first[cs] + t];
          out[0] = edge_id(tri[0]);
          out[1] = edge_id(flip ? tri[2] : tri[1]);
          out[2] = edge_id(flip ? tri[1] : tri[2]);
          out += 3;
        }
      });
    }
  }

  void fill(TriMesh& mesh) {
    std::atomic<int64_t> planes_done{0};
    const size_t plane_size = static_cast<size_t>(nx_ * ny_);
    // Ranges of at least 16 planes: each starts by renumbering one plane it does not own.
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_, 16), [&](const auto& r) {
      throw_if_cancelled(progress_);
      PlaneIds lo(plane_size), hi(plane_size);
      number_plane(r.begin(), true, lo, mesh);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        if (k + 1 < nz_) {
          number_plane(k + 1, k + 1 < r.end(), hi, mesh);  // the next range emits its own
          emit_triangles(k, lo, hi, mesh);
          std::swap(lo, hi);
        }
      }
      planes_done += r.size();
      progress_.update(double(planes_done) / double(nz_));
    });
  }

  // Vertices whose gradient vanished take the area-weighted normal of their triangles.
  void repair_zero_normals(TriMesh& mesh) const {
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

  const Volume<T>& f_;
  const McOptions& o_;
  const McTable& table_;
  Progress& progress_;
  const InsideTest<T> inside_;
  const int64_t nx_, ny_, nz_;
  std::vector<RowTrim> rows_;
  std::vector<uint64_t> vertex_first_;    // first vertex id of each z-plane's cut edges
  std::vector<uint64_t> triangle_first_;  // first triangle of each slab of cells
};

}  // namespace

template <class T>
TriMesh marching_cubes(const Volume<T>& field, const McOptions& options, Progress& progress) {
  return Extractor<T>(field, options, progress).run();
}

template TriMesh marching_cubes(const Volume<uint8_t>&, const McOptions&, Progress&);
template TriMesh marching_cubes(const Volume<int32_t>&, const McOptions&, Progress&);
template TriMesh marching_cubes(const Volume<float>&, const McOptions&, Progress&);

}  // namespace segmesh
