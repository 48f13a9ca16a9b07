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

}  // namespace segmesh::cli
