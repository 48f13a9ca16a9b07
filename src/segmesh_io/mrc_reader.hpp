// MRC / CCP4 map reader (.mrc, .map, .rec), our own rather than ITK's MRCImageIO, which ignores
// the axis order (mapc/mapr/maps) and the start indices. Internal to segmesh_io; use
// read_volume().
//
// Format: MRC2014 (https://www.ccpem.ac.uk/mrc_format/mrc2014.php). A 1024-byte header, NSYMBT
// bytes of extended header, then NC x NR x NS values (columns fastest). Either byte order
// (MACHST, or whichever order gives a sane header). Modes 0 (int8; uint8 for IMOD files without
// the signed flag), 1 (int16), 2 (float32), 6 (uint16) and 12 (float16).
//
// Result: axes reordered to x, y, z (mapc/mapr/maps say which of x, y, z the columns, rows and
// sections are). Voxel size per axis = cell length / sampling (MX, MY, MZ). Origin: the header's
// ORIGIN fields when non-zero, else start index (NCSTART... mapped to x, y, z) * voxel size.
// Direction: identity; a non-orthogonal cell (angles other than 90) is placed on orthogonal axes
// with a warning. Units are the file's own: ångström for EM maps, not millimetres.
//
// Every header field is checked against the others and against the file size before anything
// is allocated.
#pragma once

#include <filesystem>

#include "segmesh/image.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

Image read_mrc(const std::filesystem::path& path, const ReadOptions& options);

}  // namespace segmesh::volume_io
