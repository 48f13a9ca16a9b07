// The part table's text: one row per part with the numbers of part_stats.hpp as the panel shows
// them, and under each part its contacts with other parts (conforming surfaces only): the other
// part's name, the contact's area and its largest gap, as measure_scene measured them. The window
// only lays these strings out, so what it shows is what the tests check.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/scene.hpp"
#include "segmesh_viewer/part_stats.hpp"

namespace segmesh::viewer {

// The table's column titles: the cells of a row, then its contacts.
inline constexpr std::array<std::string_view, 8> kPartTableColumns = {
    "part", "triangles", "area mm2", "volume mm3", "rho min", "rho mean", "closed", "contacts"};

struct PartTableRow {
  std::array<std::string, 7> cells;  // the first seven columns
  // One line per part this one touches, in scene order: "plate_1: 36.0 mm2, gap 0.000 mm".
  // Empty for a part that touches none, and for every part of independent surfaces.
  std::vector<std::string> contacts;
};

// One contact as its line in the table.
std::string contact_text(const Scene& scene, const ContactStats& contact);

// The row of part `index` (its name, with every number empty when `stats` has no entry for it).
PartTableRow part_table_row(const Scene& scene, const std::vector<PartStats>& stats, size_t index);

// The scene's size under the meshing panel, so a decimation setting shows what it gave:
// "45236 triangles in 10 parts".
std::string triangle_count_text(const Scene& scene);

// Every part's row, in scene order.
std::vector<PartTableRow> part_table(const Scene& scene, const std::vector<PartStats>& stats);

}  // namespace segmesh::viewer
