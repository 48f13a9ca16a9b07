#include "meshing_args.hpp"

#include "segmesh/error.hpp"
#include "segmesh_io/label_names.hpp"

namespace segmesh::cli {

void add_meshing_options(CLI::App* cmd, MeshingArgs& a) {
  const MeshingOptions defaults;
  for (const MeshingOptionSpec& spec : meshing_option_specs()) {
    const std::string name(spec.name);
    if (spec.is_flag()) {
      cmd->add_flag("--no-" + name, a.negated[name], std::string(spec.help));
      continue;
    }
    CLI::Option* option =
        cmd->add_option("--" + name, a.values[name], std::string(spec.help))
            ->type_name(std::string(spec.type_name == "INT LIST" ? "INT" : spec.type_name));
    if (spec.type_name == "INT LIST") {
      option->delimiter(',');
    } else {
      option->expected(1);
      const std::string shown = spec.get(defaults);
      if (!shown.empty()) option->default_str(shown);
    }
  }
  cmd->add_option("--label-names", a.label_names,
                  "TSV file: label, name[, role bone|implant|other]");
}

MeshingOptions meshing_options(const MeshingArgs& args) {
  return resolve_meshing_options(meshing_request(args));
}

MeshingOptions meshing_request(const MeshingArgs& args) {
  MeshingOptions options;
  for (const MeshingOptionSpec& spec : meshing_option_specs()) {
    const std::string name(spec.name);
    if (spec.is_flag()) {
      if (auto it = args.negated.find(name); it != args.negated.end() && it->second) {
        spec.set(options, "false");
      }
      continue;
    }
    const auto it = args.values.find(name);
    if (it == args.values.end() || it->second.empty()) continue;
    std::string text;
    for (const std::string& item : it->second) text += (text.empty() ? "" : ",") + item;
    spec.set(options, text);
  }
  if (!args.label_names.empty()) options.label_names = read_label_names(args.label_names);
  return options;
}

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

}  // namespace segmesh::cli
