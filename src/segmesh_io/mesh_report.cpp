#include "segmesh_io/mesh_report.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/detail/json_text.hpp"

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

nlohmann::json input_json(const Image& image) {
  const Grid& grid = image.grid();
  nlohmann::json input = {{"dims", grid.dims},
                          {"spacing", grid.spacing},
                          {"origin", grid.origin},
                          {"direction", grid.direction}};
  input["path"] = image.path;
  input["type"] = image.voxel_type;
  return input;
}

// The sums over the parts the totals give.
struct Totals {
  int64_t vertices = 0, triangles = 0, voxels = 0;
  double area = 0, volume = 0, voxel_volume = 0;
  bool all_closed = true;
};

// Part p's entry (its keys in alphabetical order, as nlohmann's object writes them).
void write_part(mesh_io::JsonText& j, const Part& part, const PartMeasures& measures) {
  const MeshMeasures& m = measures.mesh;
  const QualityStats quality = measures.quality.value_or(QualityStats{});
  const double volume_before = measures.volume_before_mm3.value_or(m.volume_mm3);
  const Deviation deviation = measures.smoothing_deviation.value_or(Deviation{0, 0, 0});
  j.begin_object();
  j.member("area_mm2", m.area_mm2).member("boundary_edges", m.boundary_edges).member("closed", m.closed());
  j.member("component", part.component);
  // Decimation: null when the scene was not decimated.
  j.key("decimation");
  if (const auto& d = measures.decimation_deviation) {
    j.begin_object().member("hausdorff_mm", d->hausdorff).member("mean_mm", d->mean).member("p95_mm", d->p95);
    j.member("triangles_after", m.triangles);
    j.member("triangles_before", measures.triangles_before_decimation.value_or(0)).end_object();
  } else {
    j.null();
  }
  j.member("euler", m.euler).member("label", part.label).member("name", part.name);
  j.member("nonmanifold_edges", m.nonmanifold_edges);
  j.key("radii_ratio").begin_object().member("mean", quality.mean).member("min", quality.min).end_object();
  j.member("role", role_name(part.role)).member("shells", m.shells);
  j.key("smoothing_deviation_mm").begin_object().member("hausdorff", deviation.hausdorff);
  j.member("mean", deviation.mean).member("p95", deviation.p95).end_object();
  j.member("triangles", m.triangles).member("vertices", m.vertices);
  j.member("volume_change_percent", 100 * (m.volume_mm3 - volume_before) / volume_before);
  j.member("volume_mm3", m.volume_mm3);
  j.member("volume_vs_voxels_percent", 100 * (m.volume_mm3 - part.voxel_volume_mm3) / part.voxel_volume_mm3);
  j.member("voxel_volume_mm3", part.voxel_volume_mm3).member("voxels", part.voxels);
  j.member("winding_errors", m.winding_errors).end_object();
}

// The report up to the value of "timings_ms", which is the last thing known: the members in
// alphabetical order (contacts, input, options, outputs, parts), written as text directly, so
// that its cost per part is a small constant.
Totals write_report_head(mesh_io::JsonText& j, const Image& image, const nlohmann::json& options,
                         const Scene& scene, const SceneMeasures& scene_measures,
                         const std::vector<std::string>& outputs) {
  j.begin_object();
  // Contacts are measured on conforming surfaces only; null says they were not.
  j.key("contacts");
  if (scene.conforming) {
    j.begin_array();
    for (const ContactMeasures& c : scene_measures.contacts) {
      j.begin_object().member("area_mm2", c.area_mm2).member("max_gap_mm", c.max_gap_mm);
      j.key("parts").begin_array().value(scene.parts[c.a].name).value(scene.parts[c.b].name).end_array();
      j.end_object();
    }
    j.end_array();
  } else {
    j.null();
  }
  j.key("input").raw(input_json(image).dump(2));
  j.key("options").raw(options.dump(2));
  j.key("outputs").begin_array();
  for (const std::string& o : outputs) j.value(o);
  j.end_array();
  Totals totals;
  j.key("parts").begin_array();
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part& part = scene.parts[p];
    const MeshMeasures& m = scene_measures.parts[p].mesh;
    write_part(j, part, scene_measures.parts[p]);
    totals.vertices += m.vertices;
    totals.triangles += m.triangles;
    totals.voxels += part.voxels;
    totals.area += m.area_mm2;
    totals.volume += m.volume_mm3;
    totals.voxel_volume += part.voxel_volume_mm3;
    totals.all_closed = totals.all_closed && m.closed();
  }
  j.end_array();
  j.key("timings_ms");
  return totals;
}

// The rest: the timings and the totals.
void write_report_tail(mesh_io::JsonText& j, const MeshTimings& t, const Totals& totals,
                       const PipelineStats& stats, const Scene& scene, const SceneMeasures& measures) {
  j.begin_object().member("components", t.components).member("decimate", t.decimate);
  j.member("extract", t.extract).member("measure", t.measure).member("other", t.total - t.steps());
  j.member("read", t.read).member("report", t.report).member("smooth", t.smooth);
  j.member("total", t.total).member("write", t.write).end_object();
  double max_gap = 0;
  for (const ContactMeasures& c : measures.contacts) max_gap = std::max(max_gap, c.max_gap_mm);
  j.key("totals").begin_object().member("all_closed", totals.all_closed).member("area_mm2", totals.area);
  if (scene.conforming) j.member("contacts", measures.contacts.size());
  else j.key("contacts").null();
  j.member("dropped_components", stats.dropped_components);
  if (scene.conforming) j.member("max_contact_gap_mm", max_gap);
  else j.key("max_contact_gap_mm").null();
  j.member("parts", scene.parts.size()).member("presmooth_fallbacks", stats.presmooth_fallbacks);
  j.member("triangles", totals.triangles).member("vertices", totals.vertices);
  j.member("volume_mm3", totals.volume).member("voxel_volume_mm3", totals.voxel_volume);
  j.member("voxels", totals.voxels).end_object();
  j.end_object();
}

}  // namespace

void write_mesh_report(const std::filesystem::path& path, const Image& image,
                       const ReportedRequest& request, MeshTimings& t,
                       std::chrono::steady_clock::time_point start, const PipelineStats& stats,
                       const Scene& scene, const SceneMeasures& measures,
                       const std::vector<std::string>& outputs) {
  const auto step = std::chrono::steady_clock::now();
  mesh_io::JsonText j(2);
  const Totals totals = write_report_head(j, image, options_json(request), scene, measures, outputs);
  t.report = ms_since(step);
  // The total as the report is written: everything but the file write and what follows it.
  t.total = ms_since(start);
  write_report_tail(j, t, totals, stats, scene, measures);
  AtomicFile file(path);
  file.stream() << j.text() << '\n';
  file.commit();
}

}  // namespace segmesh
