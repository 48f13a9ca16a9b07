// libFuzzer target for the DICOM series reader. The input is one or two DICOM files: when it
// starts with "SEGMESH2" and a 4-byte little-endian length n, the next n bytes are the first
// slice and the rest the second; otherwise the whole input is one slice (a folder of one, which
// exercises the header scan and the refusal of a single slice). The folder goes through
// read_volume, which must return an image or throw segmesh::Error.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "fuzz_input.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/read_volume.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto folder = segmesh::fuzz::fresh_folder("series");
  if (size >= 12 && std::memcmp(data, "SEGMESH2", 8) == 0) {
    uint32_t first = 0;
    std::memcpy(&first, data + 8, 4);
    const size_t n = first < size - 12 ? first : size - 12;
    segmesh::fuzz::write_file(folder, "a.dcm", data + 12, n);
    segmesh::fuzz::write_file(folder, "b.dcm", data + 12 + n, size - 12 - n);
  } else {
    segmesh::fuzz::write_file(folder, "a.dcm", data, size);
  }
  segmesh::ReadOptions options;
  options.max_voxels = 16u << 20;
  try {
    const segmesh::Image image = segmesh::read_volume(folder, options);
    (void)image;
  } catch (const segmesh::Error&) {
  }
  return 0;
}
