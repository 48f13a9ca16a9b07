// libFuzzer target for the --label-names TSV reader: read_label_names must return the names or
// throw segmesh::Error.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/label_names.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path =
      segmesh::fuzz::write_file(segmesh::fuzz::scratch_folder(), "labels.tsv", data, size);
  try {
    const auto names = segmesh::read_label_names(path);
    (void)names;
  } catch (const segmesh::Error&) {
  }
  return 0;
}
