#include "segmesh/scene_measures.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

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

// The vertex positions of a mesh, to ask whether a point is one of them: open addressing
// (linear probing, at most half full) on the vertices' ids, so building it for a shell of half a
// million vertices costs a few milliseconds, where a node-based set took ten times that.
class PositionSet {
 public:
  PositionSet() = default;
  explicit PositionSet(const std::vector<Vec3f>& positions) : positions_(&positions) {
    size_t slots = 16;
    while (slots < 2 * positions.size()) slots *= 2;
    slots_.assign(slots, 0);
    mask_ = slots - 1;
    for (size_t v = 0; v < positions.size(); ++v) {
      size_t h = PositionKeyHash{}(position_key(positions[v])) & mask_;
      while (slots_[h] != 0) h = (h + 1) & mask_;
      slots_[h] = uint32_t(v + 1);
    }
  }
  bool contains(Vec3f p) const {
    if (slots_.empty()) return false;
    const PositionKey key = position_key(p);
    for (size_t h = PositionKeyHash{}(key) & mask_; slots_[h] != 0; h = (h + 1) & mask_)
      if (position_key((*positions_)[slots_[h] - 1]) == key) return true;
    return false;
  }

 private:
  const std::vector<Vec3f>* positions_ = nullptr;
  std::vector<uint32_t> slots_;  // vertex id + 1, 0 for an empty slot
  size_t mask_ = 0;
};

// The contacts of the scene's labelled surface: areas from part_contacts, and for every contact
// vertex the exact distance to both parts' shells. A shell with a vertex at exactly the contact
// vertex's position (always, when the shells were cut from the surface as it is) is at distance 0
// from it; only the other contact vertices (a shell moved or written apart, e.g. decimated) are
// searched, exactly, in a tree on that shell's own order, built only for the shells that need it.
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
  std::vector<size_t> touching;
  for (const ContactMeasures& c : out)
    for (size_t p : {c.a, c.b}) touching.push_back(p);
  std::sort(touching.begin(), touching.end());
  touching.erase(std::unique(touching.begin(), touching.end()), touching.end());
  std::vector<PositionSet> at(scene.parts.size());
  tbb::parallel_for(size_t{0}, touching.size(), [&](size_t i) {
    at[touching[i]] = PositionSet(scene.parts[touching[i]].mesh.positions);
  });
  // Per contact and side, the contact vertices that are not a vertex of that side's shell.
  std::vector<std::array<std::vector<uint32_t>, 2>> misses(out.size());
  tbb::parallel_for(size_t{0}, out.size(), [&](size_t i) {
    std::vector<uint32_t>& v = vertices[i];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    for (int side = 0; side < 2; ++side) {
      const PositionSet& shell = at[side == 0 ? out[i].a : out[i].b];
      for (uint32_t x : v)
        if (!shell.contains(surface.mesh.positions[x])) misses[i][side].push_back(x);
    }
  });
  std::vector<char> needs_tree(scene.parts.size(), 0);
  for (size_t i = 0; i < out.size(); ++i)
    for (int side = 0; side < 2; ++side)
      if (!misses[i][side].empty()) needs_tree[side == 0 ? out[i].a : out[i].b] = 1;
  std::vector<std::optional<OrderedTriangleTree>> shells(scene.parts.size());
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    const TriMesh& m = scene.parts[p].mesh;
    if (needs_tree[p] && !m.empty())
      shells[p].emplace(m.positions.data(), m.indices.data(), m.triangle_count());
  });
  tbb::parallel_for(size_t{0}, out.size(), [&](size_t i) {
    double gap2 = 0;
    for (int side = 0; side < 2; ++side) {
      const std::optional<OrderedTriangleTree>& shell = shells[side == 0 ? out[i].a : out[i].b];
      for (uint32_t x : misses[i][side]) {
        if (!shell) {
          gap2 = std::numeric_limits<double>::infinity();
          break;
        }
        gap2 = std::max(gap2, shell->nearest2(to_double(surface.mesh.positions[x]),
                                              std::numeric_limits<double>::infinity(),
                                              OrderedTriangleTree::kNoStart, 0));
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
