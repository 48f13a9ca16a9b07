// Part statistics for the viewer's table and quality view: the numbers the CLI reports for one
// part (vertices, triangles, area, enclosed volume, closedness, radii ratio minimum, mean and
// histogram, and with conforming surfaces its contacts with other parts: area and largest gap),
// taken from the core's measure_scene (segmesh/scene_measures.hpp) so the viewer and the CLI
// measure a part the same way, and their sum over the visible parts for the colour bar's
// histogram. Measures are of the mesh as meshed: a rigid move changes none of them.
// Cost: O(triangles) per part (both measures are linear).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/progress.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::viewer {

// One contact of a part with another part (ContactMeasures, seen from one of its two parts).
struct ContactStats {
  size_t other = 0;        // the other part's index in the scene
  double area_mm2 = 0;     // the common surface's area
  double max_gap_mm = 0;   // the largest distance from a contact vertex to either shell
};

struct PartStats {
  int64_t vertices = 0;
  int64_t triangles = 0;
  double area_mm2 = 0;
  double volume_mm3 = 0;
  double rho_min = 0;   // worst radii ratio
  double rho_mean = 0;
  bool closed = false;  // every edge in exactly two triangles, in opposite directions
  std::array<int64_t, 10> rho_histogram{};  // bins of width 0.1, as QualityStats::histogram
  // The parts this one touches, by their index (ContactMeasures order); empty without conforming
  // surfaces (Scene::surface) and for parts that touch no other.
  std::vector<ContactStats> contacts;
};

PartStats measure_part(const TriMesh& mesh);

// Every part's statistics, parts in parallel, with every contact listed under both its parts.
// Reports progress per part and throws Cancelled when
// `progress` is cancelled.
std::vector<PartStats> measure_parts(const Scene& scene, Progress& progress = null_progress());

// The statistics of the parts with `include[i]` true, taken together: counts, area, volume and
// histogram summed, rho_min the minimum, rho_mean weighted by triangles, closed when all are; no
// contacts.
// `include` shorter than `stats` counts as false for the missing entries.
PartStats combine_stats(const std::vector<PartStats>& stats, const std::vector<bool>& include);

}  // namespace segmesh::viewer
