// DICOM Segmentation (DICOM SEG) reader: one multi-frame file holding binary or fractional
// segment masks, as 3D Slicer, dcmqi, TotalSegmentator and PACS tools write them. Internal to
// segmesh_io; use read_volume().
//
// What it reads, and how (PS3.3 A.51, C.8.20):
// - The Segment Sequence: each segment's number becomes its label value in the label map, its
//   Segment Label the part's name and its Recommended Display CIELab Value (when present) the
//   part's colour (Image::labels), as a .seg.nrrd's segments do.
// - The frames: each names its segment (Segment Identification Sequence) and its place
//   (Plane Position Sequence), per frame or shared; the orientation and pixel spacing come from
//   the shared or per-frame functional groups and must be the same for every frame. Frames are
//   placed on one grid along the slice normal: the slice spacing is Spacing Between Slices when
//   given, else the smallest gap between distinct frame positions; a frame off that grid (more
//   than 1 % of the spacing), or beside it in the plane, is an error. Slices no frame covers
//   (writers omit empty ones) are background. Origin, spacing and direction are in patient LPS
//   millimetres, as for a DICOM series, so meshes overlay the CT they were drawn on.
// - Pixels: BINARY (1 bit, packed across frames without padding) or FRACTIONAL (8 bits, a voxel
//   is inside above half of Maximum Fractional Value), uncompressed (explicit or implicit VR
//   little endian, or deflated); an encapsulated (compressed) transfer syntax is an error saying
//   how to decompress.
// - Overlapping segments (allowed by DICOM SEG, impossible in a label map): a voxel in several
//   segments takes the highest segment number, and one warning says which segments overlapped
//   and in how many voxels.
//
// Any other single DICOM file (a CT slice) is an error asking for its series' folder.
// Robustness: the file is walked by check_dicom_file before GDCM reads it; the frame count, the
// per-frame items and the pixel data's length must agree, and the grid is checked against
// max_voxels before anything is allocated. Errors are one line naming the file.
// The label map is uint8 when every segment number is below 256, else uint16.
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_dicom_seg(const std::filesystem::path& file, const ReadOptions& options);

}  // namespace segmesh::volume_io
