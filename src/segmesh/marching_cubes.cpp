#include "segmesh/marching_cubes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "segmesh/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/marching_cubes_table.hpp"
#include "segmesh/row_trim.hpp"

namespace segmesh {

namespace {

template <class T>
class Extractor {
 public:
  Extractor(const Volume<T>& field, const McOptions& options, Progress& progress)
      : f_(field),
        o_(options),
        table_(mc_table(options.connectivity)),
        progress_(progress),
        nx_(field.grid.dims[0]),
        ny_(field.grid.dims[1]),
        nz_(field.grid.dims[2]) {}

  TriMesh run() {
    TriMesh mesh;
    if (nx_ < 2 || ny_ < 2 || nz_ < 2) return mesh;
    scan_.emplace(f_, InsideTest<T>(o_.iso), progress_);
    count();
    const uint64_t vertices = vertex_first_.back();
    if (vertices > std::numeric_limits<uint32_t>::max()) {
      throw Error("marching cubes: the surface has more than 4 billion vertices; "
                  "crop the volume or select fewer labels");
    }
    mesh.positions.resize(vertices);
    if (o_.vertex_normals) mesh.normals.resize(vertices);
    mesh.indices.resize(3 * triangle_first_.back());
    fill(mesh);
    if (o_.vertex_normals) repair_zero_normals(mesh);
    return mesh;
  }

 private:
  void count() {
    std::vector<uint64_t> vertices(nz_), triangles(nz_);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz_), [&](const auto& r) {
      throw_if_cancelled(progress_);
      for (int64_t k = r.begin(); k < r.end(); ++k) {
        uint64_t nv = 0;
        scan_->cut_edges(k, [&](int, int64_t, int64_t) { ++nv; });
        vertices[k] = nv;
        uint64_t nt = 0;
        if (k + 1 < nz_) {
          for (int64_t j = 0; j + 1 < ny_; ++j) {
            scan_->cells(j, k, [&](int64_t, int cs) { nt += table_.triangle_count(cs); });
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
  void number_plane(int64_t k, bool emit, PlaneEdgeIds& ids, TriMesh& mesh) const {
    scan_->number_plane(k, static_cast<uint32_t>(vertex_first_[k]), ids,
                        [&](int axis, int64_t i, int64_t j, uint32_t id) {
                          if (emit) emit_vertex(axis, i, j, k, id, mesh);
                        });
  }

  void emit_vertex(int axis, int64_t i, int64_t j, int64_t k, uint32_t id, TriMesh& mesh) const {
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

  void emit_triangles(int64_t k, const PlaneEdgeIds& lo, const PlaneEdgeIds& hi, TriMesh& mesh) const {
    uint32_t* out = mesh.indices.data() + 3 * triangle_first_[k];
    const bool flip = f_.grid.mirrored();
    for (int64_t j = 0; j + 1 < ny_; ++j) {
      scan_->cells(j, k, [&](int64_t i, int cs) {
        auto edge_id = [&](int e) { return cell_edge_id(lo, hi, e, i, j, nx_); };
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
      PlaneEdgeIds lo(plane_size), hi(plane_size);
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
  const int64_t nx_, ny_, nz_;
  std::optional<TrimmedScan<T>> scan_;
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
