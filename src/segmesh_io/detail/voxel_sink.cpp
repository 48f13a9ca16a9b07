#include "segmesh_io/detail/voxel_sink.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "segmesh/first_touch.hpp"
#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

float half_to_float(uint16_t h) {
  const bool negative = (h >> 15) != 0;
  const int exponent = (h >> 10) & 0x1f;
  const int mantissa = h & 0x3ff;
  float value;
  if (exponent == 0) {
    value = std::ldexp(float(mantissa), -24);  // subnormal
  } else if (exponent == 31) {
    value = mantissa != 0 ? std::numeric_limits<float>::quiet_NaN()
                          : std::numeric_limits<float>::infinity();
  } else {
    value = std::ldexp(float(mantissa | 0x400), exponent - 25);
  }
  return negative ? -value : value;
}

template <class T>
double as_double(T value) {
  if constexpr (std::is_same_v<T, Half>) {
    return half_to_float(value.bits);
  } else {
    return static_cast<double>(value);
  }
}

template <class T>
std::string value_text(T value) {
  if constexpr (std::is_integral_v<T>) {
    return std::to_string(value);
  } else {
    return std::to_string(as_double(value));
  }
}

// Values are converted in blocks of kBlockBytes file bytes, copied (and byte-swapped) into a
// local buffer first: the conversion loops then see no aliasing and vectorise, and in-place
// decoding (stage()) is safe because a block's file bytes are read before its values are written.
// Storage grows block by block inside a reservation of the whole volume, so each block's fresh
// memory is written while it is in cache and never before the file has supplied its data.

constexpr size_t kBlockBytes = 16384;
// stage() refuses a prefix larger than this (a NIfTI extension of megabytes): it would stay in
// the volume's capacity. Such files are decoded block by block instead.
constexpr size_t kMaxStagedPrefix = size_t(1) << 20;

// The storage an integer file starts in: the narrowest kind that holds every value of its type
// (a rescaled file can produce any value, so it starts in int32).
VoxelSink::IntStore initial_int_store(VoxelType type, const Rescale& rescale) {
  if (rescale.identity()) {
    switch (type) {
      case VoxelType::uint8:
        return std::vector<uint8_t>();
      case VoxelType::int8:
      case VoxelType::int16:
        return std::vector<int16_t>();
      case VoxelType::uint16:
        return std::vector<uint16_t>();
      default:
        break;
    }
  }
  return std::vector<int32_t>();
}

template <class S>
bool fits(double value) {
  return value == std::nearbyint(value) && value >= double(std::numeric_limits<S>::min()) &&
         value <= double(std::numeric_limits<S>::max());
}

}  // namespace

VoxelSink::VoxelSink(fs::path path, size_t count, VoxelType file_type, Rescale rescale)
    : path_(std::move(path)),
      count_(count),
      rescale_(rescale),
      file_type_(file_type),
      is_float_(!is_integer(file_type)),
      ints_(initial_int_store(file_type, rescale)) {
  reserve();
}

void VoxelSink::reserve() {
  if (is_float_) {
    floats_.reserve(count_);
  } else {
    std::visit([&](auto& store) { store.reserve(count_); }, ints_);
  }
}

template <class S>
S* VoxelSink::room(std::vector<S>& store, size_t n) {
  if (!store_staged_) store.resize(filled_ + n);  // within the reservation: no move
  return store.data() + filled_;
}

void VoxelSink::append(VoxelType type, const void* data, size_t n, bool swap_bytes) {
  if (filled_ + n > count_) throw std::logic_error("VoxelSink: more voxels than allocated");
  with_stored_type(type, [&](auto tag) {
    append_typed<decltype(tag)>(static_cast<const unsigned char*>(data), n, swap_bytes);
  });
}

template <class T>
void VoxelSink::append_typed(const unsigned char* data, size_t n, bool swap_bytes) {
  constexpr size_t per_block = kBlockBytes / sizeof(T);
  alignas(64) T block[per_block];
  for (size_t done = 0; done < n;) {
    const size_t k = std::min(per_block, n - done);
    std::memcpy(static_cast<void*>(block), data + done * sizeof(T), k * sizeof(T));
    if (swap_bytes) swap_bytes_inplace(block, k, sizeof(T));
    convert_block(block, k);
    done += k;
  }
}

// Converts values into the integer store of type S; stops at the first value S cannot hold (not
// a whole number, or out of range) and returns how many it stored.
template <class S, class T>
size_t VoxelSink::convert_ints(std::vector<S>& store, const T* values, size_t n) {
  S* out = room(store, n);
  if constexpr (std::is_integral_v<T>) {
    if (rescale_.identity()) {
      if constexpr (std::in_range<S>(std::numeric_limits<T>::min()) &&
                    std::in_range<S>(std::numeric_limits<T>::max())) {
        for (size_t k = 0; k < n; ++k) out[k] = static_cast<S>(values[k]);  // vectorises
        filled_ += n;
        return n;
      } else {
        for (size_t k = 0; k < n; ++k) {
          if (!std::in_range<S>(values[k])) {
            filled_ += k;
            return k;
          }
          out[k] = static_cast<S>(values[k]);
        }
        filled_ += n;
        return n;
      }
    }
  }
  // Rescaled or floating-point data in an integer file (DICOM after ITK's rescale): stays an
  // integer while every value is a whole number in range.
  for (size_t k = 0; k < n; ++k) {
    const double value = as_double(values[k]) * rescale_.slope + rescale_.intercept;
    if (!fits<S>(value)) {
      filled_ += k;
      return k;
    }
    out[k] = static_cast<S>(value);
  }
  filled_ += n;
  return n;
}

template <class T>
void VoxelSink::convert_block(const T* values, size_t n) {
  if (value_error_) {  // deferred: the volume is refused anyway, the values are only counted
    filled_ += n;
    return;
  }
  size_t i = 0;
  while (!is_float_ && i < n) {
    i += std::visit([&](auto& store) { return convert_ints(store, values + i, n - i); }, ints_);
    if (i == n) return;
    // values[i] does not fit the store: a wider integer store, or float, or a value error.
    const double value = as_double(values[i]) * rescale_.slope + rescale_.intercept;
    if (fits<int32_t>(value) && !std::holds_alternative<std::vector<int32_t>>(ints_)) {
      widen_to_int32();
      continue;
    }
    if constexpr (std::is_integral_v<T>) {
      if (rescale_.identity()) {
        Error error = file_error(path_, "voxel value " + value_text(values[i]) +
                                            " does not fit a 32-bit signed integer, which segmesh "
                                            "uses for labels; relabel the volume with values from "
                                            "-2147483648 to 2147483647");
        if (!defer_) throw error;
        value_error_ = std::move(error);
        filled_ += n - i;
        return;
      }
    }
    promote_to_float();
  }
  float* out = room(floats_, n - i);
  for (size_t k = i; k < n; ++k) {
    const double value = as_double(values[k]) * rescale_.slope + rescale_.intercept;
    out[k - i] = static_cast<float>(value);
  }
  filled_ += n - i;
}

void VoxelSink::retire_store() {
  // A staged store still holds file bytes being converted: keep it alive (moving a vector keeps
  // its buffer) until finish().
  if (store_staged_) retired_ = std::move(ints_);
  store_staged_ = false;
}

void VoxelSink::widen_to_int32() {
  std::vector<int32_t> wide;
  wide.reserve(count_);
  std::visit([&](const auto& store) {
    wide.assign(store.begin(), store.begin() + static_cast<std::ptrdiff_t>(filled_));
  }, ints_);
  retire_store();
  ints_ = std::move(wide);
}

void VoxelSink::promote_to_float() {
  floats_.reserve(count_);
  std::visit([&](const auto& store) {
    floats_.assign(store.begin(), store.begin() + static_cast<std::ptrdiff_t>(filled_));
  }, ints_);
  retire_store();
  ints_ = std::vector<int32_t>();
  is_float_ = true;
}

unsigned char* VoxelSink::stage(size_t prefix, VoxelType type) {
  const size_t size = voxel_type_size(type);
  const size_t stored = is_float_ ? sizeof(float)
                                  : std::visit([](const auto& v) { return sizeof(v[0]); }, ints_);
  if (size > stored || filled_ != 0 || store_staged_ || prefix > kMaxStagedPrefix) {
    return nullptr;
  }
  // File bytes end where the storage ends; the first voxel's bytes start at
  // (stored - size) * count or later, so widening block by block from the front writes only
  // bytes already read.
  // The whole volume is written at once by the decoder, in one thread: its fresh pages are
  // first touched from every thread beforehand (first_touch.hpp).
  const size_t elements = count_ + (prefix + stored - 1) / stored + 16;
  unsigned char* storage;
  if (is_float_) {
    resize_zeroed(floats_, elements);
    storage = reinterpret_cast<unsigned char*>(floats_.data());
  } else {
    storage = std::visit([&](auto& v) {
      resize_zeroed(v, elements);
      return reinterpret_cast<unsigned char*>(v.data());
    }, ints_);
  }
  store_staged_ = true;
  staged_data_ = storage;
  staged_at_ = elements * stored - count_ * size;
  return storage + staged_at_ - prefix;
}

void VoxelSink::append_staged(VoxelType type, bool swap_bytes) {
  if (!store_staged_ || filled_ != 0) throw std::logic_error("VoxelSink: nothing staged");
  append(type, staged_data_ + staged_at_, count_, swap_bytes);
}

void VoxelSink::clear() {
  filled_ = 0;
  value_error_.reset();
  store_staged_ = false;
  staged_data_ = nullptr;
  staged_at_ = 0;
  retired_ = std::vector<int32_t>();
  is_float_ = !is_integer(file_type_);
  ints_ = initial_int_store(file_type_, rescale_);
  std::vector<float>().swap(floats_);
  reserve();
}

AnyVolume VoxelSink::finish(const Grid& grid) && {
  if (value_error_) throw *value_error_;
  if (filled_ != count_ || grid.voxel_count() != count_) {
    throw std::logic_error("VoxelSink: voxel count does not match the grid");
  }
  retired_ = std::vector<int32_t>();
  store_staged_ = false;
  if (is_float_) {
    floats_.resize(count_);  // a staged store keeps its capacity: no copy of the volume
    return ScalarVolume{grid, std::move(floats_)};
  }
  return std::visit([&](auto& store) -> AnyVolume {
    store.resize(count_);
    using S = typename std::decay_t<decltype(store)>::value_type;
    return Volume<S>{grid, std::move(store)};
  }, ints_);
}

}  // namespace segmesh::volume_io
