// segmesh: segmented CT volumes in, watertight surface meshes out.
//
// Exit codes: 0 success, 2 a problem with the input or the request (one line on stderr,
// "segmesh: error: ..."; nothing is written), 1 an internal fault.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>
#include <string>

#include "commands.hpp"
#include "segmesh/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"segmesh: watertight surface meshes from segmented CT volumes", "segmesh"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("segmesh 0.1.0"));
  // One entry per subcommand (commands.hpp), in the order `segmesh --help` lists them.
  const segmesh::cli::Subcommand commands[] = {
      segmesh::cli::add_info_command(app),
      segmesh::cli::add_mesh_command(app),
      segmesh::cli::add_batch_command(app),
      segmesh::cli::add_phantom_command(app),
      segmesh::cli::add_quality_command(app),
      segmesh::cli::add_render_command(app),
      segmesh::cli::add_study_command(app),
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "segmesh: error: %s (see segmesh --help)\n", e.what());
    return 2;
  }
  try {
    for (const auto& command : commands) {
      if (command.parser->parsed()) return command.run();
    }
    return 2;
  } catch (const segmesh::Error& e) {
    std::fprintf(stderr, "segmesh: error: %s\n", e.what());
    return 2;
  } catch (const segmesh::Cancelled&) {
    std::fprintf(stderr, "segmesh: cancelled\n");
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A file system call that failed outside the checks (a folder that cannot be listed, a
    // file removed meanwhile): the path and the reason, never "internal error".
    std::string where = e.path1().string();
    if (where.empty()) where = "segmesh";
    std::fprintf(stderr, "segmesh: error: %s: %s\n", where.c_str(), e.code().message().c_str());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "segmesh: error: out of memory; try a smaller volume or fewer labels\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "segmesh: internal error: %s\n", e.what());
    return 1;
  }
}
