#include "segmesh_viewer/part_stats.hpp"

#include <algorithm>

#include "segmesh/scene_measures.hpp"

namespace segmesh::viewer {

namespace {

PartStats to_stats(const PartMeasures& measures) {
  PartStats s;
  const MeshMeasures& m = measures.mesh;
  if (m.triangles == 0) return s;
  const QualityStats q = measures.quality.value_or(QualityStats{});
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

}  // namespace

PartStats measure_part(const TriMesh& mesh) {
  return to_stats(segmesh::measure_part(mesh, true));
}

std::vector<PartStats> measure_parts(const Scene& scene, Progress& progress) {
  const SceneMeasures measures = measure_scene(scene, {.quality = true, .contacts = true}, progress);
  std::vector<PartStats> stats;
  stats.reserve(measures.parts.size());
  for (const PartMeasures& m : measures.parts) stats.push_back(to_stats(m));
  // Every contact under both its parts, each part's list ordered by the other part.
  for (const ContactMeasures& c : measures.contacts) {
    stats[c.a].contacts.push_back({c.b, c.area_mm2, c.max_gap_mm});
    stats[c.b].contacts.push_back({c.a, c.area_mm2, c.max_gap_mm});
  }
  for (PartStats& s : stats) {
    std::sort(s.contacts.begin(), s.contacts.end(),
              [](const ContactStats& x, const ContactStats& y) { return x.other < y.other; });
  }
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
