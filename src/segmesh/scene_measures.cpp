#include "segmesh/scene_measures.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include "segmesh/detail/ordered_triangle_tree.hpp"
#include "segmesh/moved_mesh_deviation.hpp"
#include "segmesh/position_key.hpp"

namespace segmesh {

PartMeasures measure_part(const TriMesh& mesh, bool quality, const std::vector<Vec3f>* extracted,
                          const TriMesh* undecimated) {
  PartMeasures m;
  m.mesh = measure_mesh(mesh);
  if (quality) m.quality = triangle_quality(mesh);
  const TriMesh& smoothed = undecimated ? *undecimated : mesh;
  if (extracted) {
    m.volume_before_mm3 = enclosed_volume(*extracted, smoothed.indices);
    m.smoothing_deviation = moved_mesh_deviation(*extracted, smoothed);
  }
  if (undecimated) {
    m.triangles_before_decimation = int64_t(undecimated->triangle_count());
    m.decimation_deviation = mesh_deviation(*undecimated, mesh);
  }
  return m;
}

namespace {

// A triangle of the mesh at each vertex position (the last one met).
using TriangleAt = std::unordered_map<PositionKey, uint32_t, PositionKeyHash>;
TriangleAt triangle_at(const TriMesh& m) {
  TriangleAt at;
  at.reserve(m.positions.size());
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) at[position_key(m.positions[m.indices[3 * t + size_t(k)]])] = uint32_t(t);
  return at;
}

// The contacts of the scene's labelled surface: areas from part_contacts, and for every contact
// vertex the exact distance to both parts' shells (a tree on each shell's own order). The search
// starts at a shell triangle with a vertex at the contact vertex's position, where there is one
// (there always is when the shells were cut from the surface as it is): distance 0 ends it there;
// elsewhere (a shell moved or written apart) it is the full search.
std::vector<ContactMeasures> measure_contacts(const Scene& scene) {
  const LabelledSurface& surface = *scene.surface;
  std::vector<ContactMeasures> out;
  std::map<std::pair<uint32_t, uint32_t>, size_t> index;
  for (const PartContact& c : part_contacts(surface)) {
    index[{c.a, c.b}] = out.size();
    out.push_back({c.a - 1, c.b - 1, c.area_mm2, 0});
  }
  if (out.empty()) return out;
  // Each contact's vertices, once.
  std::vector<std::vector<uint32_t>> vertices(out.size());
  for (size_t t = 0; t < surface.sides.size(); ++t) {
    const auto [in, outside] = surface.sides[t];
    if (in == 0 || outside == 0) continue;
    std::vector<uint32_t>& v = vertices[index.at({std::min(in, outside), std::max(in, outside)})];
    for (int k = 0; k < 3; ++k) v.push_back(surface.mesh.indices[3 * t + size_t(k)]);
  }
  std::vector<std::optional<OrderedTriangleTree>> shells(scene.parts.size());
  std::vector<TriangleAt> starts(scene.parts.size());
  std::vector<size_t> touching;
  for (const ContactMeasures& c : out)
    for (size_t p : {c.a, c.b}) touching.push_back(p);
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  tbb::parallel_for(size_t{0}, touching.size(), [&](size_t i) {
    const TriMesh& m = scene.parts[touching[i]].mesh;
    if (m.empty()) return;
    shells[touching[i]].emplace(m.positions.data(), m.indices.data(), m.triangle_count());
    starts[touching[i]] = triangle_at(m);
  });
  tbb::parallel_for(size_t{0}, out.size(), [&](size_t i) {
    std::vector<uint32_t>& v = vertices[i];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    double gap2 = 0;
    for (uint32_t x : v) {
      const Vec3f& position = surface.mesh.positions[x];
      const Vec3d p = to_double(position);
      for (size_t part : {out[i].a, out[i].b}) {
        if (!shells[part]) {
          gap2 = std::numeric_limits<double>::infinity();
          continue;
        }
        const auto at = starts[part].find(position_key(position));
        const size_t start = at == starts[part].end() ? OrderedTriangleTree::kNoStart : at->second;
        gap2 = std::max(
            gap2, shells[part]->nearest2(p, std::numeric_limits<double>::infinity(), start, 0));
      }
    }
    out[i].max_gap_mm = std::sqrt(gap2);
  });
  return out;
}

}  // namespace

SceneMeasures measure_scene(const Scene& scene, const MeasureRequest& request, Progress& progress) {
  const size_t n = scene.parts.size();
  const ExtractedPositions* extracted = request.extracted;
  const bool decimated = extracted && !extracted->undecimated.empty();
  if (extracted) {
    bool matches =
        extracted->parts.size() == n && (!decimated || extracted->undecimated.size() == n);
    for (size_t p = 0; matches && p < n; ++p)
      matches = extracted->parts[p].size() ==
                (decimated ? extracted->undecimated[p] : scene.parts[p].mesh).positions.size();
    if (!matches) {
      throw std::invalid_argument(
          "measure_scene: the extracted positions are not the scene's parts");
    }
  }
  progress.step("measuring");
  std::vector<double> weights;
  for (const Part& part : scene.parts) weights.push_back(double(part.mesh.triangle_count()) + 1);
  PartsProgress shared(progress, weights);
  SceneMeasures out;
  out.parts.resize(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t p) {
    throw_if_cancelled(progress);
    out.parts[p] = measure_part(scene.parts[p].mesh, request.quality,
                                extracted ? &extracted->parts[p] : nullptr,
                                decimated ? &extracted->undecimated[p] : nullptr);
    shared.done(p);
  });
  throw_if_cancelled(progress);
  if (scene.surface && request.contacts) out.contacts = measure_contacts(scene);
  return out;
}

}  // namespace segmesh
