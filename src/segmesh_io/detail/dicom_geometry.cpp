#include "segmesh_io/detail/dicom_geometry.hpp"

#include <gdcmTrace.h>

namespace segmesh::volume_io {

void set_slice_directions(Grid& grid, const std::array<double, 6>& orientation) {
  const Vec3d columns[3] = {row_direction(orientation), column_direction(orientation),
                            normal_of(orientation)};
  for (int c = 0; c < 3; ++c) {
    const double length = norm(columns[c]);
    const Vec3d unit = length > 0 ? (1.0 / length) * columns[c] : columns[c];
    grid.direction[c] = unit.x;
    grid.direction[3 + c] = unit.y;
    grid.direction[6 + c] = unit.z;
  }
}

void silence_gdcm() {
  static const bool done = [] {
    gdcm::Trace::WarningOff();
    gdcm::Trace::DebugOff();
    gdcm::Trace::ErrorOff();
    return true;
  }();
  (void)done;
}

}  // namespace segmesh::volume_io
