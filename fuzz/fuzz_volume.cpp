// libFuzzer target for one volume reader: the input becomes a file named "input" +
// SEGMESH_FUZZ_EXTENSION (.nii, .nrrd, .seg.nrrd, .mha, .mrc) and goes through read_volume, which
// must either return an image or throw segmesh::Error; anything else (a crash, a sanitizer report,
// another exception, a hang, a huge allocation) is a finding. The voxel limit is lowered so that
// a header may claim at most 64 MB of int32 voxels; libFuzzer's -rss_limit_mb catches the rest.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/read_volume.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path =
      segmesh::fuzz::write_file(segmesh::fuzz::scratch_folder(), "input" SEGMESH_FUZZ_EXTENSION,
                                data, size);
  segmesh::ReadOptions options;
  options.max_voxels = 16u << 20;
  try {
    const segmesh::Image image = segmesh::read_volume(path, options);
    (void)image;
  } catch (const segmesh::Error&) {
  }
  return 0;
}
