// The meshing options `segmesh mesh` and `segmesh render` share, registered from the options
// layer's table (meshing_option_specs in segmesh/meshing_options.hpp): the names, help texts,
// defaults, parsing and checks are the library's, so both commands, the viewer, the study and the
// report state every option the same way. --label-names (a file) is the command line's own.
#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

#include "segmesh/meshing_options.hpp"

namespace segmesh::cli {

struct MeshingArgs {
  // What was given on the command line, by option name: the text (a list's items joined by
  // commas) or, for the flags, whether --no-<name> was given.
  std::map<std::string, std::vector<std::string>, std::less<>> values;
  std::map<std::string, bool, std::less<>> negated;
  std::string label_names;
};

// Adds every option of meshing_option_specs() and --label-names to `cmd`.
void add_meshing_options(CLI::App* cmd, MeshingArgs& args);

// The options given, resolved (resolve_meshing_options); throws segmesh::Error naming the option
// at fault. Reads the --label-names file. Leaves color_by_quality false.
MeshingOptions meshing_options(const MeshingArgs& args);
// The options given, not resolved yet (for what depends on the request itself: surfaces_note).
MeshingOptions meshing_request(const MeshingArgs& args);

}  // namespace segmesh::cli
