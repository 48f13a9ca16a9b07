#include "segmesh_io/mesh_report.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "segmesh_io/atomic_file.hpp"

namespace segmesh {

namespace {

// Resolved options as the report records them (method, labels, ..., smooth, dc_*);
// `label_names` is the file they came from ("" for none).
nlohmann::json meshing_json(const MeshingOptions& o, const std::string& label_names) {
  const SmoothOptions& s = o.smooth;
  nlohmann::json j = {{"method", method_name(o.method)},
                      {"surfaces", surfaces_name(o.surfaces)},
                      {"labels", o.labels},
                      {"connectivity", o.connectivity},
                      {"min_voxels", o.min_voxels},
                      {"normals", normals_name(o.normals)},
                      {"presmooth_mm", o.volume_sigma_mm},
                      {"smooth",
                       {{"method", smooth_method_name(s.method)},
                        {"iterations", s.iterations},
                        {"lambda", s.lambda},
                        {"alpha", s.alpha},
                        {"beta", s.beta},
                        {"taubin_lambda", s.taubin_lambda},
                        {"taubin_mu", s.taubin_mu},
                        {"pass_band", s.pass_band},
                        {"sinc_unit_gain", s.sinc_unit_gain},
                        {"preserve_volume", s.preserve_volume}}},
                      {"dc_svd_eps", o.dc_svd_eps},
                      {"dc_tolerance_mm", o.dc_tolerance_mm},
                      {"decimate",
                       {{"error_mm", o.decimate.error_mm},
                        {"max_triangles", o.decimate.max_triangles},
                        {"max_triangles_per_part", o.decimate.max_triangles_per_part}}}};
  j["iso"] = o.iso ? nlohmann::json(*o.iso) : nlohmann::json(nullptr);
  j["label_names"] = label_names.empty() ? nlohmann::json(nullptr) : nlohmann::json(label_names);
  return j;
}

nlohmann::json options_json(const ReportedRequest& r) {
  nlohmann::json j = meshing_json(r.options, r.label_names);
  j["format"] = extension(r.target.format);
  j["quantize"] = r.write.quantize;
  j["output"] = r.target.path.string();
  j["per_part_files"] = r.target.folder;
  j["atlas"] = r.atlas.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.atlas);
  j["threads"] = r.threads;
  j["color"] = r.color;
  j["surfaces_note"] = r.surfaces_note ? nlohmann::json(*r.surfaces_note) : nlohmann::json(nullptr);
  return j;
}

nlohmann::json mesh_report(const Image& image, const nlohmann::json& options, const MeshTimings& t,
                           const PipelineStats& stats, const Scene& scene,
                           const SceneMeasures& scene_measures,
                           const std::vector<std::string>& outputs) {
  const std::vector<PartMeasures>& measures = scene_measures.parts;
  const Grid& grid = image.grid();
  nlohmann::json input = {{"dims", grid.dims},
                          {"spacing", grid.spacing},
                          {"origin", grid.origin},
                          {"direction", grid.direction}};
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

}  // namespace

void write_mesh_report(const std::filesystem::path& path, const Image& image,
                       const ReportedRequest& request, MeshTimings& t,
                       std::chrono::steady_clock::time_point start, const PipelineStats& stats,
                       const Scene& scene, const SceneMeasures& measures,
                       const std::vector<std::string>& outputs) {
  const auto step = std::chrono::steady_clock::now();
  // The timings are the last thing known: the report is put into text with a marker in their
  // place and its tree freed (with many parts, making the text and freeing the tree take as long
  // as the rest of the report), then they are.
  constexpr std::string_view kMarker = "segmesh:timings_ms";
  nlohmann::json timings;
  std::string text;
  {
    nlohmann::json json = mesh_report(image, options_json(request), t, stats, scene, measures, outputs);
    timings = std::move(json["timings_ms"]);
    json["timings_ms"] = kMarker;
    text = json.dump(2);
  }
  t.report = ms_since(step);
  // The total as the report is written: everything but the file write and what follows it.
  t.total = ms_since(start);
  timings["report"] = t.report;
  timings["other"] = t.total - t.steps();
  timings["total"] = t.total;
  // At depth one of the two-space indentation.
  std::string value;
  for (const char c : timings.dump(2)) {
    value += c;
    if (c == '\n') value += "  ";
  }
  const std::string quoted = "\"" + std::string(kMarker) + "\"";
  const size_t at = text.find("\"timings_ms\": " + quoted);
  if (at != std::string::npos) {
    text.replace(text.find(quoted, at), quoted.size(), value);
  }
  AtomicFile file(path);
  file.stream() << text << '\n';
  file.commit();
}

}  // namespace segmesh
