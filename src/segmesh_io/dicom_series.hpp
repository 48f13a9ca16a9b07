// DICOM series reader: a folder of single-frame DICOM slices. Internal to segmesh_io; use
// read_volume().
//
// ITK's GDCMImageIO reads each file (header, then pixels with the rescale slope/intercept
// applied). The series is assembled here:
// - Files that are not DICOM images are skipped with a warning (options.warn), as are
//   multi-frame objects (enhanced CT; a DICOM SEG is read on its own by dicom_seg_reader.hpp).
//   Subfolders are not searched.
// - Slices are grouped by series (SeriesInstanceUID, image size and orientation); when there are
//   several, the one with most slices is read and a warning names the others.
// - Slices are ordered by their position along the slice normal (ImagePositionPatient projected
//   on the cross product of the two ImageOrientationPatient directions), never by file name or
//   instance number. Two slices at one position, or a gap that differs from the others by more
//   than 1% (a missing slice), are errors naming the files; a gantry tilt is warned about.
// - Grid: origin at the first slice, columns of the direction = row direction, column direction,
//   slice normal; slice spacing from the positions (SliceThickness is ignored).
// - Image::voxel_type is the stored type; rescaled values that are all whole numbers stay an
//   integer volume (CT in HU), others become a ScalarVolume.
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_dicom_series(const std::filesystem::path& folder, const ReadOptions& options);

}  // namespace segmesh::volume_io
