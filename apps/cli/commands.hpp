// The subcommands of the `segmesh` program. Each adds its options to the parser and returns the
// function that runs it once the command line is parsed; one file per subcommand.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace segmesh::cli {

struct Subcommand {
  CLI::App* parser = nullptr;  // owned by the main parser
  std::function<int()> run;    // returns the exit code
};

Subcommand add_batch_command(CLI::App& app);
Subcommand add_info_command(CLI::App& app);
Subcommand add_mesh_command(CLI::App& app);
Subcommand add_phantom_command(CLI::App& app);
Subcommand add_quality_command(CLI::App& app);
Subcommand add_render_command(CLI::App& app);
Subcommand add_study_command(CLI::App& app);

}  // namespace segmesh::cli
