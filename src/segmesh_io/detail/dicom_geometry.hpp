// What the DICOM readers share about a slice's place in space and GDCM's manners. Internal to
// segmesh_io (dicom_series.cpp, dicom_seg_reader.cpp).
//
// ImageOrientationPatient gives the direction of a row (increasing column index) and of a column
// (increasing row index) in patient (LPS) millimetres; the slice normal is their cross product.
// Slices are stacked along the normal, so a volume's grid has the row direction, the column
// direction and the normal as the columns of its direction matrix, and its origin at the first
// slice's ImagePositionPatient.
#pragma once

#include <array>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>

#include "segmesh/grid.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh::volume_io {

// "a\b\c" (a DICOM multi-valued decimal string) as N finite numbers, or nullopt.
template <size_t N>
std::optional<std::array<double, N>> dicom_numbers(const std::optional<std::string>& text) {
  if (!text) return std::nullopt;
  std::array<double, N> values{};
  std::string item;
  std::istringstream items(*text);
  for (size_t i = 0; i < N; ++i) {
    if (!std::getline(items, item, '\\')) return std::nullopt;
    char* end = nullptr;
    values[i] = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || !std::isfinite(values[i])) return std::nullopt;
  }
  return values;
}

inline Vec3d row_direction(const std::array<double, 6>& o) {
  return {o[0], o[1], o[2]};
}
inline Vec3d column_direction(const std::array<double, 6>& o) {
  return {o[3], o[4], o[5]};
}
// The unit slice normal (zero when the two directions are parallel or zero).
inline Vec3d normal_of(const std::array<double, 6>& o) {
  const Vec3d n = cross(row_direction(o), column_direction(o));
  const double length = norm(n);
  return length > 0 ? (1.0 / length) * n : n;
}

// grid.direction from ImageOrientationPatient: row direction, column direction, normal, each
// normalised (check_grid then refuses one that is not orthonormal).
void set_slice_directions(Grid& grid, const std::array<double, 6>& orientation);

// GDCM reports what it dislikes on stderr, several lines at a time; segmesh gives one line
// (warnings through ReadOptions::warn, errors as Error). Switched off once, before GDCM is used.
void silence_gdcm();

}  // namespace segmesh::volume_io
