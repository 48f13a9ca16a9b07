// The cases of a cohort run (`segmesh batch INPUTS...`) from what the user names, in order:
//
//   a volume file      one case (also when it is missing: the case fails, the rest go on)
//   a folder           every volume file in it and below it (volume_extension), and every
//                      folder below holding no volume file and no sub-folder whose first file
//                      starts like DICOM (a series); the folder itself when it holds only files
//                      and none is a volume file (a DICOM series, as `segmesh mesh` reads it).
//                      Hidden entries and the output folder are left out. Sorted by path.
//   a glob             "scans/*/seg.nii.gz" (quoted, so the shell leaves it): the matches, sorted
//   a manifest         a .csv or .tsv file with a header row: a `path` column (relative paths
//                      are relative to the manifest's folder), optionally a `case` column (the
//                      case's name) and columns named like the meshing options of `segmesh mesh`
//                      (`smooth`, `iterations`, `labels`, `min_voxels`, `label_names`, ...;
//                      '_' or '-'), whose non-empty cells are that case's options
//
// Case names come from case_name (the file name without its extension) or the manifest's `case`
// column; where files share a name, the folders above them go in front until the names differ
// ("s0001/ct.nii.gz" and "s0002/ct.nii.gz" are "s0001_ct" and "s0002_ct"), and what still
// collides gets "_2", "_3", ..., compared in lower case. They are given to
// the whole list before any shard is taken, so every shard names a case the same way.
//
// Errors: segmesh::Error in one line, naming the argument or "<manifest>:<line>": a glob or
// folder that matches no volume, a manifest without a path column, with an unknown column, a
// row with too many fields or an empty path. A per-case option that does not parse or is out of
// range is reported by case_options.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "segmesh/meshing_options.hpp"
#include "segmesh_io/case_runner.hpp"
#include "segmesh_io/mesh_format.hpp"

namespace segmesh {

struct CohortCase {
  std::filesystem::path input;
  std::string name;
  // Manifest cells by option name ("iterations", "label-names"), in column order.
  std::vector<std::pair<std::string, std::string>> options;
  std::string origin;  // "<manifest>:<line>" for a manifest row, else empty
  std::filesystem::path manifest_folder;  // what a relative label-names cell is relative to
};

// `exclude`: the output folder, never searched for inputs.
std::vector<CohortCase> expand_cohort_inputs(const std::vector<std::string>& inputs,
                                             const std::filesystem::path& exclude = {});

// `defaults` (a request, e.g. the command line's) with the case's own options set through the
// options layer (meshing_option_specs), still a request (the runner resolves it; surfaces_note
// needs the request). Resolved once here, so a bad cell is refused before any case runs: segmesh::Error "<manifest>:<line>: --smooth must be ...". A `label-names` cell is read
// (relative to the manifest's folder) and its path stored in `label_names_file`.
MeshingOptions case_options(const MeshingOptions& defaults, const CohortCase& c,
                            std::string& label_names_file);

// What every case of a cohort run shares: `segmesh batch`'s options other than the inputs, OUT
// and the shard (the Python runner's settings, the same).
struct CohortSettings {
  MeshingOptions defaults;       // a request; each case's manifest cells go on top (case_options)
  std::string label_names_file;  // the file defaults.label_names came from, for the report
  MeshFormat format = MeshFormat::glb;
  bool per_part = false;
  MeshWriteOptions write;
  std::string color = "material";
  int threads = 0;
  ReadOptions read{.allow_external_data = false};  // external data only when asked for
  bool force = false;
};

// The settings' format from its name ("--format"); throws segmesh::Error otherwise.
MeshFormat cohort_format(const std::string& name);
// Checks the settings as `segmesh batch` states them, before any case runs: --quantize only
// with glb, --color material or quality, --threads not negative, --max-voxels at least 1.
// Throws segmesh::Error.
void check_cohort_settings(const CohortSettings& settings);
// OUT as a cohort run takes it: normalised, without a trailing "/".
std::filesystem::path cohort_output_folder(const std::filesystem::path& output);
// The case's request: the settings, then its own manifest cells (case_options, which checks
// them: segmesh::Error naming the manifest line).
CaseRequest case_request(const CohortCase& c, const std::filesystem::path& out_dir,
                         const CohortSettings& settings);

// `--shard I/N`: this run takes the cases whose index (0-based, in input order) modulo N is
// I - 1, so shards 1..N together take every case exactly once.
struct Shard {
  int index = 1;
  int count = 1;
  bool takes(size_t case_index) const {
    return static_cast<int>(case_index % static_cast<size_t>(count)) == index - 1;
  }
};
// Parses "I/N" (1 <= I <= N); throws segmesh::Error naming --shard otherwise.
Shard parse_shard(std::string_view text);

}  // namespace segmesh
