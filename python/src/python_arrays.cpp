#include "python_arrays.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::python {

namespace {

std::string shape_text(const py::buffer_info& info) {
  std::string text;
  for (py::ssize_t d : info.shape) text += (text.empty() ? "" : "x") + std::to_string(d);
  return text;
}

// The voxels of a 3-D strided array indexed [i, j, k] as segmesh stores them (i fastest): one
// copy, a plain memcpy when the array is Fortran-ordered (as nibabel's are).
template <class Out, class In>
std::vector<Out> copy_voxels(const py::buffer_info& info, const std::array<int64_t, 3>& dims) {
  std::vector<Out> out(static_cast<size_t>(dims[0] * dims[1] * dims[2]));
  const auto* base = static_cast<const char*>(info.ptr);
  const py::ssize_t s0 = info.strides[0], s1 = info.strides[1], s2 = info.strides[2];
  if (std::is_same_v<In, Out> && s0 == py::ssize_t(sizeof(In)) && s1 == s0 * dims[0] &&
      s2 == s1 * dims[1]) {
    std::memcpy(out.data(), base, out.size() * sizeof(Out));
    return out;
  }
  const auto load = [](const char* p) {
    In v;
    std::memcpy(&v, p, sizeof(In));
    return static_cast<Out>(v);
  };
  if (std::abs(s0) <= std::abs(s2)) {
    // i is the array's faster axis (Fortran-like): rows of i copied one by one.
    tbb::parallel_for(int64_t{0}, dims[2], [&](int64_t k) {
      for (int64_t j = 0; j < dims[1]; ++j) {
        Out* row = out.data() + (k * dims[1] + j) * dims[0];
        const char* src = base + k * s2 + j * s1;
        for (int64_t i = 0; i < dims[0]; ++i) row[i] = load(src + i * s0);
      }
    });
    return out;
  }
  // k is the faster axis (C order, numpy's and torch's default): a transpose, in blocks of 64 k
  // so that reads run along k and the 64 rows written stay in cache.
  constexpr int64_t kBlock = 64;
  tbb::parallel_for(int64_t{0}, dims[1], [&](int64_t j) {
    for (int64_t k0 = 0; k0 < dims[2]; k0 += kBlock) {
      const int64_t k1 = std::min(dims[2], k0 + kBlock);
      for (int64_t i = 0; i < dims[0]; ++i) {
        const char* src = base + i * s0 + j * s1;
        for (int64_t k = k0; k < k1; ++k) out[size_t((k * dims[1] + j) * dims[0] + i)] = load(src + k * s2);
      }
    }
  });
  return out;
}

template <class Out, class In>
AnyVolume make_volume(const py::buffer_info& info, const Grid& grid) {
  return Volume<Out>{grid, copy_voxels<Out, In>(info, grid.dims)};
}

Held held_type(const py::array& array) {
  const char kind = array.dtype().kind();
  const py::ssize_t size = array.itemsize();
  if (kind == 'b' || (kind == 'u' && size == 1)) return Held::u8;
  if (kind == 'i' && size == 1) return Held::i8_to_i16;
  if (kind == 'i' && size == 2) return Held::i16;
  if (kind == 'u' && size == 2) return Held::u16;
  if (kind == 'i' && size == 4) return Held::i32;
  if (kind == 'f' && size == 4) return Held::f32;
  if (kind == 'f' && size == 8) return Held::f64_to_f32;
  throw Error("array: dtype " + std::string(py::str(array.dtype())) +
              " is not supported; give uint8, uint16, int16 or int32 labels, or float32/float64 "
              "grey values with iso");
}

}  // namespace

AnyVolume volume_from(const ArrayInput& in) {
  const py::buffer_info& info = in.info;
  const Grid& grid = in.grid;
  switch (in.held) {
    case Held::u8: return make_volume<uint8_t, uint8_t>(info, grid);
    case Held::i8_to_i16: return make_volume<int16_t, int8_t>(info, grid);
    case Held::i16: return make_volume<int16_t, int16_t>(info, grid);
    case Held::u16: return make_volume<uint16_t, uint16_t>(info, grid);
    case Held::i32: return make_volume<int32_t, int32_t>(info, grid);
    case Held::f32: return make_volume<float, float>(info, grid);
    case Held::f64_to_f32: return make_volume<float, double>(info, grid);
  }
  throw std::logic_error("unknown held type");
}

ArrayInput check_array(const py::object& labels, const std::array<double, 3>& spacing,
                       const std::array<double, 3>& origin, const std::array<double, 9>& direction,
                       uint64_t max_voxels) {
  if (!py::isinstance<py::array>(labels)) {
    throw Error("array: expected a numpy array, got " +
                std::string(py::str(labels.get_type().attr("__name__"))));
  }
  ArrayInput in{labels.cast<py::array>(), {}, {}};
  in.info = in.array.request();
  in.dtype = py::str(in.array.dtype());
  for (py::ssize_t d : in.info.shape) {
    if (d == 0) throw Error("array: empty (shape " + shape_text(in.info) + "); nothing to mesh");
  }
  in.grid.spacing = spacing;
  in.grid.origin = origin;
  in.grid.direction = Mat3d{direction[0], direction[1], direction[2], direction[3], direction[4],
                            direction[5], direction[6], direction[7], direction[8]};
  const std::vector<int64_t> dims(in.info.shape.begin(), in.info.shape.end());
  in.grid.dims = check_volume_geometry("array", dims, in.grid, {.max_voxels = max_voxels});
  in.held = held_type(in.array);
  return in;
}

}  // namespace segmesh::python
