// The decimation step of the pipeline (decimation.hpp): the options' check, the scene's budget
// shared between independent parts by area, and decimate_scene, which decimates the scene's
// surface (shells cut again) or every part's mesh on its own, in parallel. The collapses
// themselves are decimation.cpp's.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "segmesh/decimation.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

std::optional<DecimateOptionsProblem> decimate_options_problem(const DecimateOptions& o) {
  if (!(o.error_mm >= 0) || !std::isfinite(o.error_mm))
    return DecimateOptionsProblem{"decimate-error", "must be a non-negative number of millimetres"};
  if (o.max_triangles < 0)
    return DecimateOptionsProblem{"max-triangles", "must not be negative (0: no budget)"};
  if (o.max_triangles_per_part < 0)
    return DecimateOptionsProblem{"max-triangles-per-part", "must not be negative (0: no budget)"};
  return std::nullopt;
}

std::vector<int64_t> part_triangle_budgets(const std::vector<double>& areas,
                                           const DecimateOptions& o) {
  const double total = std::accumulate(areas.begin(), areas.end(), 0.0);
  std::vector<int64_t> out(areas.size(), 0);
  if (o.max_triangles > 0 && total > 0) {
    // Shares of the scene's budget by area, each at least the minimum a part keeps (rounded
    // down): the factor f found by bisection so that they add up to the budget at most. Plain
    // shares left small parts below the minimum, which they keep anyway, and the scene above its
    // budget (50 844 for 50 000 on a map of 54 parts).
    const auto shares = [&](double f, std::vector<int64_t>& b) {
      int64_t sum = 0;
      for (size_t p = 0; p < areas.size(); ++p) {
        b[p] = std::max<int64_t>(kMinPartTriangles, int64_t(std::floor(f * areas[p])));
        sum += b[p];
      }
      return sum;
    };
    double lo = 0, hi = double(o.max_triangles) / total;
    if (shares(hi, out) > o.max_triangles) {
      for (int k = 0; k < 64; ++k) {
        const double mid = 0.5 * (lo + hi);
        (shares(mid, out) <= o.max_triangles ? lo : hi) = mid;
      }
      shares(lo, out);  // every part at the minimum when even that is over the budget
    }
  }
  for (int64_t& b : out) {
    if (o.max_triangles_per_part > 0) {
      b = b > 0 ? std::min(b, o.max_triangles_per_part) : o.max_triangles_per_part;
    }
  }
  return out;
}

DecimationStats decimate_scene(Scene& scene, const DecimateOptions& options) {
  if (!options.active()) return {};
  if (scene.surface) {
    // One surface, one order of collapses: the scene's budget is the surface's, so the error
    // evens out over the parts instead of each part stopping at its area's share.
    const std::vector<int64_t> per_part(scene.parts.size(), options.max_triangles_per_part);
    const DecimationStats stats =
        decimate_surface(*scene.surface, options, per_part, options.max_triangles);
    set_part_shells(scene);
    return stats;
  }
  std::vector<double> areas;
  for (const Part& part : scene.parts) areas.push_back(surface_area(part.mesh));
  const std::vector<int64_t> budgets = part_triangle_budgets(areas, options);
  std::vector<DecimationStats> each(scene.parts.size());
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    TriMesh& mesh = scene.parts[p].mesh;
    if (mesh.empty()) return;
    LabelledSurface one;
    one.mesh.positions = std::move(mesh.positions);
    one.mesh.indices = std::move(mesh.indices);
    one.sides.assign(one.mesh.indices.size() / 3, {1, 0});
    one.part_count = 1;
    const int64_t budget[1] = {budgets[p]};
    each[p] = decimate_surface(one, options, budget);
    mesh = TriMesh{};
    mesh.positions = std::move(one.mesh.positions);
    mesh.indices = std::move(one.mesh.indices);
    compute_vertex_normals(mesh);
  });
  DecimationStats stats;
  for (const DecimationStats& s : each) {
    stats.collapses += s.collapses;
    stats.flips += s.flips;
    stats.largest_cost_mm = std::max(stats.largest_cost_mm, s.largest_cost_mm);
  }
  return stats;
}

}  // namespace segmesh
