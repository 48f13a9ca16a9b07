// A numpy array as the core's Image: checked with the readers' own checks (check_volume_geometry)
// and its dtype decided with the GIL held; its voxels copied, i fastest, with the GIL released.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstdint>
#include <string>

#include "segmesh/grid.hpp"
#include "segmesh/volume.hpp"

namespace segmesh::python {

namespace py = pybind11;

// How an array's dtype is held by the core: integer label maps in uint8, int16, uint16 or int32
// (bool and int8 widened), floating point as float (for --iso).
enum class Held { u8, i8_to_i16, i16, u16, i32, f32, f64_to_f32 };

struct ArrayInput {
  py::array array;
  py::buffer_info info;  // keeps the array's buffer until the run is over
  Grid grid;
  Held held = Held::u8;
  std::string dtype;  // numpy's name, the Image's voxel_type
};

// Checks `labels` (a 3-D numpy array indexed [i, j, k], not empty, a supported dtype) and its
// geometry (LPS; direction row-major); segmesh::Error "array: ..." otherwise. GIL held.
ArrayInput check_array(const py::object& labels, const std::array<double, 3>& spacing,
                       const std::array<double, 3>& origin, const std::array<double, 9>& direction,
                       uint64_t max_voxels);

// The voxels copied into the core's volume: a memcpy when the array is Fortran-ordered. Calls no
// Python: runs without the GIL.
AnyVolume volume_from(const ArrayInput& in);

}  // namespace segmesh::python
