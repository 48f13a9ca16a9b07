// write_case_summary: a cohort's summary.csv, one row per case in input order:
//
//   case,input,status,parts,triangles,volume_mm3,seconds,error
//
// status is ok, failed, skipped (finished by an earlier run; its numbers are that run's) or
// pending (not run yet: the summary of a run that was stopped). volume_mm3 is the parts' enclosed
// volumes summed; seconds the case's wall time; error the failure's one line. Fields holding a
// comma, a quote or a line break are quoted as RFC 4180 says. Written atomically (AtomicFile), so
// a reader, or a run killed while writing it, always finds a complete file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "segmesh_io/case_runner.hpp"

namespace segmesh {

void write_case_summary(const std::filesystem::path& file, const std::vector<CaseResult>& rows);

// The summary's file name: "summary.csv", or "summary-I-of-N.csv" for shard I of N (each shard
// writes its own, so shards sharing OUT never write the same file).
std::string summary_file_name(int shard, int shard_count);

}  // namespace segmesh
