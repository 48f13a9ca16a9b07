#include "segmesh/joint_smoothing.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/detail/smoothing_sweeps.hpp"
#include "segmesh/detail/surface_roles.hpp"
#include "segmesh/detail/volume_restoration.hpp"

namespace segmesh {

namespace {

// The cubics of the parts (VolumeCubic), indexed by material, added block by block.
struct PartCubics {
  std::vector<VolumeCubic> of;
  PartCubics operator+(const PartCubics& o) const {
    PartCubics sum = o.of.size() > of.size() ? o : *this;
    const PartCubics& other = o.of.size() > of.size() ? *this : o;
    for (size_t m = 0; m < other.of.size(); ++m) sum.of[m] = sum.of[m] + other.of[m];
    return sum;
  }
};

}  // namespace

void smooth_jointly(LabelledSurface& surface, const SmoothOptions& options, Progress& progress) {
  if (const auto problem = smooth_options_problem(options)) {
    throw std::invalid_argument("smooth_jointly: " + std::string(problem->option) + " " +
                                problem->rule);
  }
  TriMesh& mesh = surface.mesh;
  if (options.method == SmoothMethod::none || mesh.positions.empty()) return;
  const int iterations =
      options.iterations > 0 ? options.iterations : default_smooth_iterations(options.method);
  const size_t nv = mesh.positions.size();
  const std::vector<uint32_t>& idx = mesh.indices;
  const Triangles triangles{idx.data(), triangle_chunks(idx)};
  const SurfaceRoles topology = surface_roles(surface);
  const std::vector<Vec3f> original = mesh.positions;
  const Vec3f* o = original.data();
  const Vec3d centre = box_centre(mesh.positions);

  FilterRun run = run_filter(triangles, o, nv, options, iterations, progress, &topology.smooth);
  const F4* counts = run.counts();
  // Smoothed positions relative to the centre (fixed vertices: their own).
  std::vector<Vec3d> smoothed(nv);
  for_each_vertex(nv, [&](size_t i) {
    smoothed[i] = counts[i][3] > 0 ? run.gain * (to_d(o[i]) - centre) + xyz_d(run.d[i])
                                   : to_d(o[i]) - centre;
  });
  run = FilterRun{};
  mesh.normals.clear();

  std::vector<Restoration> restore(surface.part_count + 1);
  std::vector<Vec3d> normal;
  if (options.preserve_volume) {
    // Unit normals of the vertices the restoration moves (zero for the others, which then count
    // as fixed in every part's cubic).
    F4Buffer area(nv);
    F4* a = area.data();
    add_area_vectors(
        triangles,
        [&](uint32_t i) {
          const Vec3d p = smoothed[i];
          return F4{float(p.x), float(p.y), float(p.z), 0.0f};
        },
        a);
    normal.assign(nv, Vec3d{});
    for_each_vertex(nv, [&](size_t i) {
      if (topology.free_material[i] != 0) normal[i] = xyz_d(unit_or(a[i], F4{}));
    });
    const size_t nt = surface.sides.size();
    const PartCubics k = block_sum<PartCubics>(nt, [&](size_t t0, size_t t1) {
      PartCubics s;
      s.of.resize(surface.part_count + 1);
      for (size_t t = t0; t < t1; ++t) {
        const uint32_t* x = &idx[3 * t];
        const auto [inside, outside] = surface.sides[t];
        auto add = [&](uint32_t m, uint32_t p, uint32_t q, uint32_t r) {
          add_triangle_cubic(s.of[m], to_d(o[p]) - centre, to_d(o[q]) - centre,
                             to_d(o[r]) - centre, smoothed[p], smoothed[q], smoothed[r],
                             normal[p], normal[q], normal[r]);
        };
        add(inside, x[0], x[1], x[2]);
        if (outside != 0) add(outside, x[0], x[2], x[1]);  // the other side, turned around
      }
      return s;
    });
    for (size_t m = 1; m < k.of.size(); ++m) restore[m] = solve_restoration(k.of[m]);
  }
  for_each_vertex(nv, [&](size_t i) {
    const uint32_t m = topology.free_material[i];
    if (m != 0 && restore[m].keep_original) return;  // a speck: its background vertices as they were
    Vec3d p = centre + smoothed[i];
    if (m != 0 && restore[m].delta != 0) p = p + restore[m].delta * normal[i];
    mesh.positions[i] = to_float(p);
  });
  repair_folds(mesh, original, topology.smooth.role);
}

}  // namespace segmesh
