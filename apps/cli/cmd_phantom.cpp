// segmesh phantom -o FILE [--size X,Y,Z] [--spacing SX,SY,SZ]: writes the built-in demo volume.
#include <cstdio>

#include "cli_common.hpp"
#include "commands.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh_io/write_volume.hpp"

namespace segmesh::cli {

namespace {
struct PhantomArgs {
  std::string output;
  std::string size = "512,512,203";
  std::string spacing = "0.197,0.197,2";
  bool quiet = false;
};
}  // namespace

Subcommand add_phantom_command(CLI::App& app) {
  auto args = std::make_shared<PhantomArgs>();
  CLI::App* cmd = app.add_subcommand(
      "phantom",
      "Write the built-in demo label map: a fractured tibia (two fragments) and a fibula "
      "(label 1), a fixation plate with screws (label 2)");
  cmd->add_option("-o,--output", args->output, "output volume (.nii.gz, .nii, .nrrd, .mha)")
      ->required();
  cmd->add_option("--size", args->size, "voxels X,Y,Z")->capture_default_str();
  cmd->add_option("--spacing", args->spacing, "voxel size in mm SX,SY,SZ")->capture_default_str();
  cmd->add_flag("--quiet", args->quiet, "print nothing");
  return {cmd, [args] {
            PhantomOptions options;
            options.size = parse_triple<int64_t>(args->size, "--size");
            options.spacing = parse_triple<double>(args->spacing, "--spacing");
            const LabelVolume phantom = make_phantom(options);
            write_volume(phantom, args->output);
            if (!args->quiet) {
              std::printf("wrote %s (%lld x %lld x %lld voxels at %g x %g x %g mm)\n",
                          args->output.c_str(), (long long)options.size[0],
                          (long long)options.size[1], (long long)options.size[2],
                          options.spacing[0], options.spacing[1], options.spacing[2]);
            }
            return 0;
          }};
}

}  // namespace segmesh::cli
