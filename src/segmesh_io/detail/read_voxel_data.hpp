// read_voxel_data: a volume file's voxel data moved into a VoxelSink in one pass. Internal to
// segmesh_io: the NIfTI, NRRD, MetaImage and MRC readers decode their raw and gzip data with it.
//
// A gzip stream whose trailer agrees with the header's size is inflated by libdeflate straight
// into the sink's storage (gzip_in_place.hpp); anything else (raw data, zlib streams, several
// members, a trailer that disagrees, a corrupt or short stream) goes through DataStream block by
// block (data_stream.hpp). Guarantees: truncated data are refused with the exact byte counts, a
// corrupt stream is an Error, a compressed stream must end properly; both paths give the same
// voxels and the same errors. Cost: one pass over the file; memory grows only with the data
// actually found (voxel_sink.hpp).
#pragma once

#include <cstdint>
#include <filesystem>

#include "segmesh_io/detail/voxel_sink.hpp"
#include "segmesh_io/detail/voxel_type.hpp"

namespace segmesh::volume_io {

// `count` voxels of `type` that start `skip` bytes into the bytes of `source` from byte `offset`
// (inflated first when `compressed`), into `sink`. Errors name `path` (the header file) for
// truncated data and `source` for a corrupt stream.
void read_voxel_data(const std::filesystem::path& path, const std::filesystem::path& source,
                     uint64_t offset, bool compressed, uint64_t skip, uint64_t count,
                     VoxelType type, bool swap_bytes, VoxelSink& sink);

}  // namespace segmesh::volume_io
