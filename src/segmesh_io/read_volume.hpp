// read_volume: load a segmentation (label map) or a grey-value volume from any supported format.
//
// Formats, chosen by the file name's extension (a folder is a DICOM series):
//   .nii .nii.gz             NIfTI-1 and NIfTI-2 (either byte order; gzip detected by content)
//   .nrrd .nhdr .seg.nrrd    NRRD, detached data, 3D Slicer segmentations (segment names, colours
//                            and label values become Image::labels)
//   .mha .mhd                MetaImage
//   .mrc .map .rec           MRC / CCP4 maps (axis order mapc/mapr/maps honoured)
//   <folder>                 one DICOM series, slices ordered by their position in space
//   .dcm .dicom .ima, or a   a DICOM SEG object (dicom_seg_reader.hpp): its segments become the
//   file with the DICM magic  label values, their names and colours Image::labels; any other
//                            single DICOM file is an error asking for its series' folder
//
// Guarantees:
// - Geometry is in ITK's LPS convention, as ITK reports it for the file (NIfTI-1, NRRD,
//   MetaImage, DICOM), so meshes overlay the image in 3D Slicer. Voxels are x fastest.
//   NIfTI-2, which ITK 5.2 cannot read, uses the sform (else qform, else pixdim) converted
//   from RAS to LPS. MRC maps have no orientation: identity direction, and every length in the
//   file's own unit, which for EM maps is the ångström (not mm).
// - Integer voxel types keep the narrowest of uint8, int16, uint16 and int32 that holds the file's
//   type (image.hpp); float types become a ScalarVolume. A rescale
//   (NIfTI scl_slope/scl_inter, DICOM rescale slope/intercept) keeps integers as long as every
//   rescaled value is a whole number. Image::voxel_type names the type stored in the file.
// - Before allocating anything, the header is checked: 3-D (a 4-D/5-D file only if its extra
//   axes have size 1), positive finite spacing, at most max_voxels voxels, and a file that can
//   hold all the data it claims (raw data: the file's size; compressed data: the best ratio
//   deflate reaches). Compressed data are inflated once, straight into the volume, and counted
//   as they are: memory is touched only as data arrive (all at once only for a gzip member whose
//   trailer agrees with the header), a short stream is refused with the exact byte counts, and
//   the stream must end properly. ITK alone would accept truncated or inconsistent files.
// - Only regular files are read (a named pipe would block, a device never end), also as a
//   detached data file. Every DICOM file is walked by our own structural check before GDCM sees
//   it (dicom_file_check.hpp): a truncated or corrupt slice is an Error naming it, a file that is
//   not DICOM is skipped with a warning (an Error when it is named *.dcm).
//
// Errors: segmesh::Error with one line naming the file first, saying what is wrong and what to
// do ("seg.nii.gz: file is truncated (expected 1048576 bytes of image data, found 1000000)").
// No ITK exception escapes.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>

#include "segmesh/image.hpp"

namespace segmesh {

struct ReadOptions {
  uint64_t max_voxels = 2'000'000'000;           // refuse larger volumes before allocating
  std::function<void(const std::string&)> warn;  // receives warnings (may be empty)
  // false: a detached header (NRRD "data file", MetaImage ElementDataFile) whose data file lies
  // outside the header's own folder (an absolute path elsewhere, "../", a symbolic link out of
  // it) is refused, and so are NRRD data lists and patterns (several files, not checked one by
  // one). For runs over inputs from many sources, where a header naming /etc/passwd should not
  // be read and meshed without a word. The error names the option that allows it.
  bool allow_external_data = true;
};

// Reads the volume at `path` (a file, or a folder holding a DICOM series).
Image read_volume(const std::filesystem::path& path, const ReadOptions& options = {});

// The volume extension `path`'s file name ends with, in lower case (".nii.gz", ".seg.nrrd",
// ".nrrd", ".mha", ...); empty when it names none of the formats read_volume reads by extension.
std::string volume_extension(const std::filesystem::path& path);

// The checks read_volume makes on what a file claims, for a volume that comes from elsewhere (the
// Python package's arrays): 3-D (more axes only if every extra one has size 1), at most
// options.max_voxels voxels, positive finite spacing, a finite origin and an orthonormal
// direction. `grid`'s dims are ignored. Returns the three spatial dims. Throws the readers' own
// segmesh::Error, naming `name` first ("array: 4-D images are not supported (dims 2x3x4x5); ...").
std::array<int64_t, 3> check_volume_geometry(const std::string& name,
                                             std::span<const int64_t> dims, const Grid& grid,
                                             const ReadOptions& options = {});

}  // namespace segmesh
