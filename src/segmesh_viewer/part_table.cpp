#include "segmesh_viewer/part_table.hpp"

#include <cstdio>

namespace segmesh::viewer {

namespace {

std::string fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace

std::string contact_text(const Scene& scene, const ContactStats& contact) {
  const std::string other = contact.other < scene.parts.size()
                                ? scene.parts[contact.other].name
                                : "part " + std::to_string(contact.other);
  return other + ": " + fixed(contact.area_mm2, 1) + " mm2, gap " + fixed(contact.max_gap_mm, 3) +
         " mm";
}

PartTableRow part_table_row(const Scene& scene, const std::vector<PartStats>& stats, size_t index) {
  PartTableRow row;
  if (index < scene.parts.size()) row.cells[0] = scene.parts[index].name;
  if (index >= stats.size()) return row;
  const PartStats& s = stats[index];
  row.cells[1] = std::to_string(s.triangles);
  row.cells[2] = fixed(s.area_mm2, 1);
  row.cells[3] = fixed(s.volume_mm3, 1);
  row.cells[4] = fixed(s.rho_min, 3);
  row.cells[5] = fixed(s.rho_mean, 3);
  row.cells[6] = s.closed ? "yes" : "no";
  for (const ContactStats& c : s.contacts) row.contacts.push_back(contact_text(scene, c));
  return row;
}

std::string triangle_count_text(const Scene& scene) {
  size_t triangles = 0;
  for (const Part& part : scene.parts) triangles += part.mesh.triangle_count();
  return std::to_string(triangles) + " triangles in " + std::to_string(scene.parts.size()) +
         (scene.parts.size() == 1 ? " part" : " parts");
}

std::vector<PartTableRow> part_table(const Scene& scene, const std::vector<PartStats>& stats) {
  std::vector<PartTableRow> rows;
  rows.reserve(scene.parts.size());
  for (size_t i = 0; i < scene.parts.size(); ++i) rows.push_back(part_table_row(scene, stats, i));
  return rows;
}

}  // namespace segmesh::viewer
