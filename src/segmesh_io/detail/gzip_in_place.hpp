// The one-call gzip path of read_voxel_data.hpp: a file's gzip data inflated by libdeflate in one
// call straight into the VoxelSink's own storage, then widened there in place. Internal to
// segmesh_io.
//
// Why: the common .nii.gz (and gzip NRRD or MetaImage) is one gzip member; inflating it whole is
// faster than zlib's block-by-block inflate, and into the volume's storage there is no second copy
// of the volume. Guarantees: it applies only when the data are one gzip member whose trailer
// (ISIZE, the inflated size mod 2^32) agrees with the size the header claims, and the volume's
// storage is touched only then; for anything else (other members, zlib streams, a trailer that
// disagrees, a corrupt or short stream) it returns false with the sink as new, and the caller
// streams the data through zlib, which gives the exact diagnosis. Cost: the compressed file is
// mapped, not read; one inflate and one conversion pass over the volume.
#pragma once

#include <cstdint>
#include <filesystem>

#include "segmesh_io/detail/voxel_sink.hpp"
#include "segmesh_io/detail/voxel_type.hpp"

namespace segmesh::volume_io {

// `count` voxels of `type` that start `skip` bytes into the inflated gzip data of `source` from
// byte `offset`, into `sink`. True when done; false (sink as new) when the data are not one
// agreeing gzip member or do not inflate to exactly that size.
bool inflate_gzip_in_place(const std::filesystem::path& source, uint64_t offset, uint64_t skip,
                           uint64_t count, VoxelType type, bool swap_bytes, VoxelSink& sink);

}  // namespace segmesh::volume_io
