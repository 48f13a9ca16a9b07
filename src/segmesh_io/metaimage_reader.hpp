// MetaImage reader (.mha, .mhd with one detached data file). Internal to segmesh_io; use
// read_volume().
//
// ITK's MetaImageIO supplies the geometry. The voxels are read here, because MetaIO reads a
// truncated or corrupt data block "successfully" (it prints a complaint and returns garbage):
// the data's type, byte order, compression and location come from our own parse of the header,
// and are checked against what the header claims before anything is allocated. ASCII data and
// data split over several files (ElementDataFile = LIST or a pattern) are refused.
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_metaimage(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace segmesh::volume_io
