#include "segmesh_viewer/part_stats.hpp"

#include <algorithm>
#include <atomic>
#include <tbb/parallel_for.h>

#include "segmesh/mesh_measures.hpp"
#include "segmesh/quality.hpp"

namespace segmesh::viewer {

PartStats measure_part(const TriMesh& mesh) {
  PartStats s;
  if (mesh.empty()) return s;
  const MeshMeasures m = measure_mesh(mesh);
  const QualityStats q = triangle_quality(mesh);
  s.vertices = m.vertices;
  s.triangles = m.triangles;
  s.area_mm2 = m.area_mm2;
  s.volume_mm3 = m.volume_mm3;
  s.closed = m.closed();
  s.rho_min = q.min;
  s.rho_mean = q.mean;
  s.rho_histogram = q.histogram;
  return s;
}

std::vector<PartStats> measure_parts(const Scene& scene, Progress& progress) {
  const size_t n = scene.parts.size();
  std::vector<PartStats> stats(n);
  progress.step("measuring");
  std::atomic<size_t> done{0};
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    if (progress.cancelled()) return;
    stats[i] = measure_part(scene.parts[i].mesh);
    progress.update(double(++done) / double(n));
  });
  throw_if_cancelled(progress);
  return stats;
}

PartStats combine_stats(const std::vector<PartStats>& stats, const std::vector<bool>& include) {
  PartStats all;
  double rho_sum = 0;
  bool any = false;
  all.closed = true;
  for (size_t i = 0; i < stats.size() && i < include.size(); ++i) {
    if (!include[i]) continue;
    const PartStats& s = stats[i];
    all.vertices += s.vertices;
    all.triangles += s.triangles;
    all.area_mm2 += s.area_mm2;
    all.volume_mm3 += s.volume_mm3;
    all.closed = all.closed && s.closed;
    if (s.triangles > 0) {
      all.rho_min = any ? std::min(all.rho_min, s.rho_min) : s.rho_min;
      any = true;
      rho_sum += s.rho_mean * double(s.triangles);
    }
    for (size_t b = 0; b < all.rho_histogram.size(); ++b) all.rho_histogram[b] += s.rho_histogram[b];
  }
  if (all.triangles > 0) all.rho_mean = rho_sum / double(all.triangles);
  if (!any) all.closed = false;
  return all;
}

}  // namespace segmesh::viewer
