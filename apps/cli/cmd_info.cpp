// segmesh info INPUT [--json]: what a volume holds — grid, voxel type, value range, and for a
// label map every label with its voxel count, physical volume, connected components and name.
#include <cstdio>
#include <string>
#include <type_traits>
#include <variant>

#include "cli_common.hpp"
#include "commands.hpp"
#include "segmesh/components.hpp"
#include "segmesh/error.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/label_names.hpp"

namespace segmesh::cli {

namespace {

struct InfoArgs {
  std::string input;
  std::string label_names;
  int connectivity = kDefaultConnectivity;
  bool json = false;
  ReadArgs read;
};

struct LabelRow {
  int32_t label;
  int64_t voxels;
  double volume_mm3;
  int64_t components;
  std::string name;
};

int run_info(const InfoArgs& args) {
  // Checked by the options layer, as `segmesh mesh` checks it.
  MeshingOptions request;
  request.connectivity = args.connectivity;
  resolve_meshing_options(request);
  const Image image = read_input(args.input, args.read);
  std::vector<LabelInfo> names = image.labels;
  if (!args.label_names.empty()) {
    for (LabelInfo& info : read_label_names(args.label_names)) {
      std::erase_if(names, [&](const LabelInfo& n) { return n.label == info.label; });
      names.push_back(std::move(info));
    }
  }
  const Grid& g = image.grid();
  const ValueRange range = std::visit([](const auto& v) { return value_range(v); }, image.volume);

  // A label map lists its labels; grey values (float, or too many distinct integers) do not.
  std::vector<LabelRow> rows;
  size_t distinct = 0;
  bool label_map = image.is_integer();
  std::visit(
      [&](const auto& labels) {
        using T = typename std::decay_t<decltype(labels.voxels)>::value_type;
        if constexpr (std::is_integral_v<T>) {
          const auto counts = count_labels(labels);
          distinct = counts.size();
          label_map = distinct <= kMaxLabelsWithoutSelection;
          if (!label_map) return;
          const Components components = find_components(labels, {.connectivity = args.connectivity});
          for (const LabelCount& c : counts) {
            if (c.label == 0) continue;
            LabelRow row{c.label, c.voxels, double(c.voxels) * g.voxel_volume(), 0, ""};
            for (const Component& comp : components.components) row.components += comp.label == c.label;
            if (const LabelInfo* info = find_label_info(names, c.label)) row.name = info->name;
            rows.push_back(row);
          }
        }
      },
      image.volume);

  if (args.json) {
    nlohmann::json j = grid_json(g);
    j["path"] = image.path;
    j["voxel_type"] = image.voxel_type;
    j["kind"] = label_map ? "labels" : "grey";
    j["value_range"] = {{"min", range.min}, {"max", range.max}};
    if (range.non_finite) j["non_finite_voxels"] = range.non_finite;
    if (image.is_integer()) j["distinct_values"] = distinct;
    if (label_map) {
      j["connectivity"] = args.connectivity;
      j["labels"] = nlohmann::json::array();
      for (const LabelRow& r : rows) {
        j["labels"].push_back({{"label", r.label},
                               {"voxels", r.voxels},
                               {"volume_mm3", r.volume_mm3},
                               {"components", r.components},
                               {"name", r.name}});
      }
    }
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  // Adding 0.0 prints -0 as 0.
  Mat3d d = g.direction;
  for (double& x : d) x += 0.0;
  std::printf("%s\n", image.path.c_str());
  std::printf("  voxel type  %s (%s)\n", image.voxel_type.c_str(),
              label_map ? "label map" : "grey values");
  std::printf("  dims        %lld x %lld x %lld (%zu voxels)\n", (long long)g.dims[0],
              (long long)g.dims[1], (long long)g.dims[2], g.voxel_count());
  std::printf("  spacing     %g x %g x %g mm\n", g.spacing[0], g.spacing[1], g.spacing[2]);
  std::printf("  origin      %g, %g, %g mm (LPS)\n", g.origin[0], g.origin[1], g.origin[2]);
  std::printf("  direction   [%g %g %g; %g %g %g; %g %g %g]%s\n", d[0], d[1], d[2], d[3], d[4],
              d[5], d[6], d[7], d[8], g.mirrored() ? " (mirrored)" : "");
  std::printf("  values      %g .. %g", range.min, range.max);
  if (range.non_finite) std::printf(" (%lld NaN or infinite voxels)", (long long)range.non_finite);
  std::printf("\n");
  if (!label_map) {
    if (image.is_integer()) std::printf("  distinct    %zu values\n", distinct);
    std::printf("  mesh it with --iso VALUE (e.g. 200 for bone in CT Hounsfield units)\n");
    return 0;
  }
  std::printf("  labels      %zu (components with %d-connectivity)\n", rows.size(),
              args.connectivity);
  std::printf("  %8s %12s %14s %11s  %s\n", "label", "voxels", "volume_mm3", "components", "name");
  for (const LabelRow& r : rows) {
    std::printf("  %8d %12lld %14.1f %11lld  %s\n", r.label, (long long)r.voxels, r.volume_mm3,
                (long long)r.components, r.name.c_str());
  }
  return 0;
}

}  // namespace

Subcommand add_info_command(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "info", "Show a volume's grid, voxel type, value range and labels with their components");
  cmd->add_option("input", args->input, "volume file or DICOM folder")->required();
  cmd->add_flag("--json", args->json, "print JSON");
  cmd->add_option("--label-names", args->label_names, "TSV file: label, name[, role]");
  cmd->add_option("--connectivity", args->connectivity,
                  std::string(find_meshing_option("connectivity")->help))
      ->capture_default_str();
  add_read_options(cmd, args->read);
  return {cmd, [args] { return run_info(*args); }};
}

}  // namespace segmesh::cli
