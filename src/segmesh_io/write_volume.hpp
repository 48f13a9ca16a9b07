// write_volume: save a label map as NIfTI (.nii, .nii.gz), NRRD (.nrrd) or MetaImage (.mha),
// chosen by the file name's extension, through ITK's ImageIO classes.
//
// - The voxels are stored in the smallest type that holds every value (uint8, int16, uint16,
//   else int32), so label maps stay small and open in 3D Slicer, ITK-SNAP and nibabel alike.
//   .nrrd and .mha data are compressed; .nii only when the name ends in .gz.
// - Geometry (dims, spacing, origin, direction, LPS) is written as ITK writes it, so
//   read_volume() gives the same grid back (NIfTI keeps it in single precision, ~1e-6 relative).
// - The file appears complete or not at all: ITK writes a temporary file in the same folder
//   (AtomicFile, whose temporary name keeps the extension), which is renamed at the end; on any
//   failure no file, temporary or final, is left behind.
//
// Errors: segmesh::Error naming the file (unknown extension, missing folder, ITK write failure).
// A volume whose voxel count does not match its grid, or whose spacing is not positive, is a
// programming error (std::invalid_argument).
#pragma once

#include <filesystem>

#include "segmesh/volume.hpp"

namespace segmesh {

void write_volume(const LabelVolume& volume, const std::filesystem::path& path);

}  // namespace segmesh
