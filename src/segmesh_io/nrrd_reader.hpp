// NRRD reader (.nrrd, .nhdr with detached data, 3D Slicer .seg.nrrd). Internal to segmesh_io;
// use read_volume().
//
// ITK's NrrdImageIO reads the header and the geometry. The data's location and encoding are
// scanned here first, and raw or gzip data (attached or in one detached file) are measured against
// what the header claims before anything is allocated, then decoded here (read_voxel_data.hpp);
// ITK reads the voxels only for the other encodings.
//
// 3D Slicer segmentations keep their segments in header keys: SegmentN_Name, SegmentN_Color
// ("r g b", 0..1), SegmentN_LabelValue and SegmentN_Layer. They become Image::labels. Segments
// that overlap are stored by Slicer in several layers (a 4-D array); that is refused with a
// message saying how to export a flat label map instead.
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_nrrd(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace segmesh::volume_io
