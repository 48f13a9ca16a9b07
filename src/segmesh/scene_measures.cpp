#include "segmesh/scene_measures.hpp"

#include <tbb/parallel_for.h>

#include <stdexcept>

#include "segmesh/moved_mesh_deviation.hpp"

namespace segmesh {

PartMeasures measure_part(const TriMesh& mesh, bool quality, const std::vector<Vec3f>* extracted) {
  PartMeasures m;
  m.mesh = measure_mesh(mesh);
  if (quality) m.quality = triangle_quality(mesh);
  if (extracted) {
    m.volume_before_mm3 = enclosed_volume(*extracted, mesh.indices);
    m.smoothing_deviation = moved_mesh_deviation(*extracted, mesh);
  }
  return m;
}

std::vector<PartMeasures> measure_scene(const Scene& scene, const MeasureRequest& request,
                                        Progress& progress) {
  const size_t n = scene.parts.size();
  const ExtractedPositions* extracted = request.extracted;
  if (extracted) {
    bool matches = extracted->parts.size() == n;
    for (size_t p = 0; matches && p < n; ++p)
      matches = extracted->parts[p].size() == scene.parts[p].mesh.positions.size();
    if (!matches) {
      throw std::invalid_argument("measure_scene: the extracted positions are not the scene's parts");
    }
  }
  progress.step("measuring");
  std::vector<double> weights;
  for (const Part& part : scene.parts) weights.push_back(double(part.mesh.triangle_count()) + 1);
  PartsProgress shared(progress, weights);
  std::vector<PartMeasures> out(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t p) {
    throw_if_cancelled(progress);
    out[p] = measure_part(scene.parts[p].mesh, request.quality,
                          extracted ? &extracted->parts[p] : nullptr);
    shared.done(p);
  });
  throw_if_cancelled(progress);
  return out;
}

}  // namespace segmesh
