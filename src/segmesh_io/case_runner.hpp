// run_case: one case of a cohort (`segmesh batch`, the Python package's run_case), from its
// volume file to a complete case folder OUT/CASE holding the meshes and report.json, or to a
// failure recorded in one line, never a half-written folder.
//
// A case folder is written as a hidden sibling, OUT/.CASE.tmp-<pid>, and renamed to OUT/CASE
// when everything in it is written; its last file is case.json, the completion marker: the
// case's summary row (case_summary.hpp) and its input. A case whose OUT/CASE/case.json exists
// and names the same input is finished: run_case skips it (status skipped, with the numbers of
// the run that made it) unless `force`. A redone case replaces the old folder only once the new
// one is complete (the old one is renamed aside, then removed). Temporary folders of this case
// left by a killed run (.CASE.tmp-*, .CASE.old-*) are removed first; they never count as done.
//
// Failure isolation: any error of the case (a missing, corrupt or truncated file, a request the
// volume cannot satisfy, a full disk, out of memory) becomes status failed with a one-line
// message naming the file, and nothing of the case is left in OUT. Only Cancelled (the caller's
// progress asked to stop) propagates, after the temporary folder is removed.
//
// Meshing is run_mesh_job (mesh_job.hpp): the pipeline, measure_scene and the writers of
// `segmesh mesh`, so report.json is what `segmesh mesh --report` writes for the same options.
// No fsync: the rename makes the complete folder appear at once to every process; durability
// across a power loss is not promised (such a case may need --force).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "segmesh/meshing_options.hpp"
#include "segmesh/progress.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh {

enum class CaseStatus { ok, failed, skipped, pending };
std::string_view case_status_name(CaseStatus status);  // "ok", "failed", "skipped", "pending"

// One row of a cohort's summary.
struct CaseResult {
  std::string name;   // the case folder's name
  std::string input;  // the input as given
  CaseStatus status = CaseStatus::pending;
  int64_t parts = 0;
  int64_t triangles = 0;
  double volume_mm3 = 0;  // the parts' enclosed volumes summed
  double seconds = 0;     // wall time of the run that meshed it (read to rename)
  std::string error;      // failed: one line
};

struct CaseRequest {
  std::filesystem::path input;    // a volume file or a DICOM series folder
  std::string name;               // the case folder's name (case_name, made unique by the caller)
  std::filesystem::path out_dir;  // OUT, which must exist: the case goes to OUT/name
  MeshingOptions options;         // as requested; resolved by the runner (an error fails the case)
  std::string label_names;        // the file options.label_names came from, for the report
  MeshFormat format = MeshFormat::glb;
  bool per_part = false;  // one file per part in OUT/CASE instead of OUT/CASE/scene.<format>
  MeshWriteOptions write;
  std::string color = "material";  // or "quality"
  int threads = 0;                 // for the report only: the caller limits the threads
  ReadOptions read;                // a cohort run sets allow_external_data = false
  bool force = false;              // redo a finished case
};

// Runs one case (see the top of this file). Throws only Cancelled.
CaseResult run_case(const CaseRequest& request, Progress& progress = null_progress());

// The finished case OUT/name for `input`, as its case.json records it; nullopt when the folder or
// its marker is missing, unreadable, or names another input.
std::optional<CaseResult> finished_case(const std::filesystem::path& out_dir,
                                        const std::string& name,
                                        const std::filesystem::path& input);

// Removes the hidden siblings a killed run of case `name` left in `out_dir` (.name.tmp-<pid>,
// .name.old-<pid>; never another case's). run_case does it first; a scheduler that gives up on
// a case whose worker died (the Python package's Dask runner) does it for that case.
void remove_case_temporaries(const std::filesystem::path& out_dir, const std::string& name);

// A case's name from its input: the file name without its volume extension (volume_extension:
// .nii.gz, .seg.nrrd, .nrrd, ...), a DICOM folder's own name; characters other than ASCII
// letters, digits, '-', '_' and '.' become '_', leading and trailing dots are dropped, at most
// 100 characters, and an empty name becomes "case".
std::string case_name(const std::filesystem::path& input);

}  // namespace segmesh
