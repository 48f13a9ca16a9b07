#include "mesh_report.hpp"

#include <algorithm>
#include <cstdio>

#include "cli_common.hpp"

namespace segmesh::cli {

nlohmann::json mesh_report(const Image& image, const nlohmann::json& options, const Timings& t,
                           const PipelineStats& stats, const Scene& scene,
                           const SceneMeasures& scene_measures,
                           const std::vector<std::string>& outputs) {
  const std::vector<PartMeasures>& measures = scene_measures.parts;
  nlohmann::json input = grid_json(image.grid());
  input["path"] = image.path;
  input["type"] = image.voxel_type;
  nlohmann::json parts = nlohmann::json::array();
  int64_t vertices = 0, triangles = 0, voxels = 0;
  double area = 0, volume = 0, voxel_volume = 0;
  bool all_closed = true;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part& part = scene.parts[p];
    const MeshMeasures& m = measures[p].mesh;
    const QualityStats quality = measures[p].quality.value_or(QualityStats{});
    const double volume_before = measures[p].volume_before_mm3.value_or(m.volume_mm3);
    const Deviation deviation = measures[p].smoothing_deviation.value_or(Deviation{0, 0, 0});
    // Decimation: null when the scene was not decimated.
    nlohmann::json decimation = nullptr;
    if (const auto& d = measures[p].decimation_deviation) {
      decimation = {{"triangles_before", measures[p].triangles_before_decimation.value_or(0)},
                     {"triangles_after", m.triangles},
                     {"hausdorff_mm", d->hausdorff},
                     {"p95_mm", d->p95},
                     {"mean_mm", d->mean}};
    }
    parts.push_back({{"name", part.name},
                     {"label", part.label},
                     {"component", part.component},
                     {"role", role_name(part.role)},
                     {"voxels", part.voxels},
                     {"voxel_volume_mm3", part.voxel_volume_mm3},
                     {"vertices", m.vertices},
                     {"triangles", m.triangles},
                     {"area_mm2", m.area_mm2},
                     {"volume_mm3", m.volume_mm3},
                     {"closed", m.closed()},
                     {"boundary_edges", m.boundary_edges},
                     {"nonmanifold_edges", m.nonmanifold_edges},
                     {"winding_errors", m.winding_errors},
                     {"shells", m.shells},
                     {"euler", m.euler},
                     {"radii_ratio", {{"min", quality.min}, {"mean", quality.mean}}},
                     {"volume_change_percent",
                      100 * (m.volume_mm3 - volume_before) / volume_before},
                     {"volume_vs_voxels_percent",
                      100 * (m.volume_mm3 - part.voxel_volume_mm3) / part.voxel_volume_mm3},
                     {"smoothing_deviation_mm",
                      {{"hausdorff", deviation.hausdorff},
                       {"mean", deviation.mean},
                       {"p95", deviation.p95}}},
                     {"decimation", decimation}});
    vertices += m.vertices;
    triangles += m.triangles;
    voxels += part.voxels;
    area += m.area_mm2;
    volume += m.volume_mm3;
    voxel_volume += part.voxel_volume_mm3;
    all_closed = all_closed && m.closed();
  }
  // Contacts are measured on conforming surfaces only; null says they were not.
  nlohmann::json contacts = nullptr;
  double max_gap = 0;
  if (scene.conforming) {
    contacts = nlohmann::json::array();
    for (const ContactMeasures& c : scene_measures.contacts) {
      contacts.push_back({{"parts", {scene.parts[c.a].name, scene.parts[c.b].name}},
                          {"area_mm2", c.area_mm2},
                          {"max_gap_mm", c.max_gap_mm}});
      max_gap = std::max(max_gap, c.max_gap_mm);
    }
  }
  return {{"input", input},
          {"options", options},
          {"timings_ms",
           {{"read", t.read},
            {"components", t.components},
            {"extract", t.extract},
            {"smooth", t.smooth},
            {"decimate", t.decimate},
            {"write", t.write},
            {"measure", t.measure},
            {"report", t.report},
            {"other", t.total - t.steps()},
            {"total", t.total}}},
          {"outputs", outputs},
          {"parts", parts},
          {"contacts", contacts},
          {"totals",
           {{"parts", scene.parts.size()},
            {"vertices", vertices},
            {"triangles", triangles},
            {"voxels", voxels},
            {"voxel_volume_mm3", voxel_volume},
            {"area_mm2", area},
            {"volume_mm3", volume},
            {"all_closed", all_closed},
            {"dropped_components", stats.dropped_components},
            {"presmooth_fallbacks", stats.presmooth_fallbacks},
            {"contacts", scene.conforming ? nlohmann::json(scene_measures.contacts.size())
                                          : nlohmann::json(nullptr)},
            {"max_contact_gap_mm",
             scene.conforming ? nlohmann::json(max_gap) : nlohmann::json(nullptr)}}}};
}

std::string summary_table(const Scene& scene, const std::vector<PartMeasures>& measures) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-28s %-8s %10s %11s %14s %14s %7s %6s\n", "part", "role",
                "voxels", "triangles", "voxel_mm3", "mesh_mm3", "closed", "shells");
  out += line;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part& part = scene.parts[p];
    const MeshMeasures& m = measures[p].mesh;
    std::snprintf(line, sizeof line, "%-28s %-8s %10lld %11lld %14.1f %14.1f %7s %6lld\n",
                  part.name.c_str(), std::string(role_name(part.role)).c_str(),
                  (long long)part.voxels, (long long)m.triangles, part.voxel_volume_mm3,
                  m.volume_mm3, m.closed() ? "yes" : "NO", (long long)m.shells);
    out += line;
  }
  return out;
}

}  // namespace segmesh::cli
