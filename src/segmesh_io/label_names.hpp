// read_label_names: the names and roles of label values from a tab-separated file (the CLI's
// --label-names), e.g. ../shared/data/totalsegmentator/labels.tsv.
//
// Format: one label per line, `label<TAB>name[<TAB>role]`, role bone, implant or other (any
// case; absent: decided by defaults later). Blank lines and lines starting with '#' are ignored;
// the first remaining line may be a header (its first field is not a number). Windows line ends
// are accepted. Entries come back in file order.
//
// Errors: segmesh::Error "<file>:<line>: <what is wrong>" for a malformed line (label not an
// integer, missing name, unknown role, more than three fields, a label listed twice), and
// "<file>: ..." for a missing or unreadable file or one without any entry.
#pragma once

#include <filesystem>
#include <vector>

#include "segmesh/label_info.hpp"

namespace segmesh {

std::vector<LabelInfo> read_label_names(const std::filesystem::path& tsv);

}  // namespace segmesh
