// NIfTI-1 / NIfTI-2 reader (.nii, .nii.gz). Internal to segmesh_io; use read_volume().
//
// The header is parsed here (both versions, either byte order, gzip recognised by its magic
// bytes rather than the extension) and validated before anything is allocated: dim[0] must be 3
// (4 or 5 only with extra axes of size 1), pixdim[1..3] positive and finite, a supported
// datatype, and the (inflated) file must hold vox_offset + voxels * bytes. ITK's NiftiImageIO
// supplies the NIfTI-1 geometry (its qform/sform choice, in LPS); NIfTI-2, which ITK 5.2 cannot
// read, uses the sform, else the qform, else pixdim alone. Voxels are read here, in one pass,
// with scl_slope/scl_inter applied (see VoxelSink for when integers stay integers).
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_nifti(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace segmesh::volume_io
