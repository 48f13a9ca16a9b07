#include "segmesh_io/volume_data.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "segmesh_io/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

struct Half {
  uint16_t bits;
};

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

// Calls f(T{}) with the C++ type stored for `type`.
template <class F>
void with_stored_type(VoxelType type, F&& f) {
  switch (type) {
    case VoxelType::uint8:
      return f(uint8_t{});
    case VoxelType::int8:
      return f(int8_t{});
    case VoxelType::uint16:
      return f(uint16_t{});
    case VoxelType::int16:
      return f(int16_t{});
    case VoxelType::uint32:
      return f(uint32_t{});
    case VoxelType::int32:
      return f(int32_t{});
    case VoxelType::uint64:
      return f(uint64_t{});
    case VoxelType::int64:
      return f(int64_t{});
    case VoxelType::float16:
      return f(Half{});
    case VoxelType::float32:
      return f(float{});
    case VoxelType::float64:
      return f(double{});
  }
}

}  // namespace

std::string_view voxel_type_name(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return "uint8";
    case VoxelType::int8:
      return "int8";
    case VoxelType::uint16:
      return "uint16";
    case VoxelType::int16:
      return "int16";
    case VoxelType::uint32:
      return "uint32";
    case VoxelType::int32:
      return "int32";
    case VoxelType::uint64:
      return "uint64";
    case VoxelType::int64:
      return "int64";
    case VoxelType::float16:
      return "float16";
    case VoxelType::float32:
      return "float32";
    case VoxelType::float64:
      return "float64";
  }
  return "unknown";
}

size_t voxel_type_size(VoxelType type) {
  size_t size = 0;
  with_stored_type(type, [&](auto tag) { size = sizeof(tag); });
  return size;
}

bool is_integer(VoxelType type) {
  return type != VoxelType::float16 && type != VoxelType::float32 && type != VoxelType::float64;
}

void swap_bytes_inplace(void* data, size_t count, size_t size) {
  auto* bytes = static_cast<unsigned char*>(data);
  for (size_t i = 0; i < count; ++i) std::reverse(bytes + i * size, bytes + (i + 1) * size);
}

// ---------------------------------------------------------------------------------------------
// VoxelSink

VoxelSink::VoxelSink(fs::path path, size_t count, VoxelType file_type, Rescale rescale)
    : path_(std::move(path)), count_(count), rescale_(rescale), is_float_(!is_integer(file_type)) {
  if (is_float_) {
    floats_.resize(count);
  } else {
    ints_.resize(count);
  }
}

void VoxelSink::append(VoxelType type, const void* data, size_t n, bool swap_bytes) {
  if (filled_ + n > count_) throw std::logic_error("VoxelSink: more voxels than allocated");
  with_stored_type(type, [&](auto tag) {
    append_typed<decltype(tag)>(static_cast<const unsigned char*>(data), n, swap_bytes);
  });
}

template <class T>
void VoxelSink::append_typed(const unsigned char* data, size_t n, bool swap_bytes) {
  size_t i = 0;
  if (!is_float_) {
    int32_t* out = ints_.data() + filled_;
    if constexpr (std::is_integral_v<T>) {
      if (rescale_.identity()) {
        for (; i < n; ++i) {
          const T value = load_value<T>(data + i * sizeof(T), swap_bytes);
          if constexpr (!std::in_range<int32_t>(std::numeric_limits<T>::min()) ||
                        !std::in_range<int32_t>(std::numeric_limits<T>::max())) {
            if (!std::in_range<int32_t>(value)) {
              throw file_error(path_, "voxel value " + value_text(value) +
                                          " does not fit a 32-bit signed integer, which segmesh "
                                          "uses for labels; relabel the volume with values from "
                                          "-2147483648 to 2147483647");
            }
          }
          out[i] = static_cast<int32_t>(value);
        }
        filled_ += n;
        return;
      }
    }
    // Rescaled or floating-point data in an integer file (DICOM after ITK's rescale): stays
    // int32 while every value is a whole number in range.
    for (; i < n; ++i) {
      const double value =
          as_double(load_value<T>(data + i * sizeof(T), swap_bytes)) * rescale_.slope +
          rescale_.intercept;
      if (!(value == std::nearbyint(value) && value >= INT32_MIN && value <= INT32_MAX)) break;
      out[i] = static_cast<int32_t>(value);
    }
    filled_ += i;
    if (i == n) return;
    promote_to_float();
  }
  float* out = floats_.data() + filled_;
  for (size_t k = i; k < n; ++k) {
    const double value =
        as_double(load_value<T>(data + k * sizeof(T), swap_bytes)) * rescale_.slope +
        rescale_.intercept;
    out[k - i] = static_cast<float>(value);
  }
  filled_ += n - i;
}

void VoxelSink::promote_to_float() {
  floats_.resize(count_);
  std::copy(ints_.begin(), ints_.begin() + static_cast<std::ptrdiff_t>(filled_), floats_.begin());
  std::vector<int32_t>().swap(ints_);
  is_float_ = true;
}

std::variant<LabelVolume, ScalarVolume> VoxelSink::finish(const Grid& grid) && {
  if (filled_ != count_ || grid.voxel_count() != count_) {
    throw std::logic_error("VoxelSink: voxel count does not match the grid");
  }
  if (is_float_) return ScalarVolume{grid, std::move(floats_)};
  return LabelVolume{grid, std::move(ints_)};
}

// ---------------------------------------------------------------------------------------------
// DataStream

struct DataStream::Impl {
  fs::path path;
  std::ifstream file;
  bool compressed = false;
  z_stream z{};
  bool z_ready = false;
  bool input_done = false;  // the file has no more bytes
  bool ended = false;       // compressed: the last member ended cleanly
  std::vector<unsigned char> in;

  ~Impl() {
    if (z_ready) inflateEnd(&z);
  }

  Error corrupt(const char* reason) const {
    return file_error(path, std::string("the compressed image data is corrupt (") +
                                (reason ? reason : "inflate failed") + "); the file is damaged");
  }

  // Keeps unread input and appends more; false when the file has nothing more.
  bool refill() {
    if (input_done) return false;
    const size_t kept = z.avail_in;
    if (kept > 0 && z.next_in != in.data()) std::memmove(in.data(), z.next_in, kept);
    file.read(reinterpret_cast<char*>(in.data() + kept), std::streamsize(in.size() - kept));
    const auto got = static_cast<size_t>(file.gcount());
    if (got == 0) input_done = true;
    z.next_in = in.data();
    z.avail_in = static_cast<uInt>(kept + got);
    return got > 0;
  }

  size_t read_compressed(unsigned char* out, size_t n) {
    size_t produced = 0;
    while (produced < n && !ended) {
      if (z.avail_in == 0 && !refill()) break;  // input ends inside a member: truncated
      const auto room = static_cast<uInt>(std::min<size_t>(n - produced, UINT_MAX));
      z.next_out = out + produced;
      z.avail_out = room;
      const int status = inflate(&z, Z_NO_FLUSH);
      produced += room - z.avail_out;
      if (status == Z_STREAM_END) {
        // bgzip and concatenated gzip files hold several members; anything else after the
        // stream is ignored, as gzip does.
        if (z.avail_in < 2) refill();
        if (z.avail_in >= 2 && z.next_in[0] == 0x1f && z.next_in[1] == 0x8b) {
          inflateReset(&z);
        } else {
          ended = true;
        }
      } else if (status == Z_BUF_ERROR) {
        if (!refill()) break;
      } else if (status != Z_OK) {
        throw corrupt(z.msg);
      }
    }
    return produced;
  }
};

DataStream::DataStream(const fs::path& path, uint64_t offset, bool compressed)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->compressed = compressed;
  impl_->file.open(path, std::ios::binary);
  if (!impl_->file) {
    throw file_error(path, std::string("cannot open the file (") + std::strerror(errno) + ")");
  }
  impl_->file.seekg(static_cast<std::streamoff>(offset));
  if (!impl_->file) throw file_error(path, "cannot read the file (seeking to its data failed)");
  if (compressed) {
    impl_->in.resize(size_t(1) << 18);
    // 15 + 32: accept zlib and gzip headers alike.
    if (inflateInit2(&impl_->z, 15 + 32) != Z_OK) throw std::bad_alloc();
    impl_->z_ready = true;
  }
}

DataStream::~DataStream() = default;

size_t DataStream::read(void* out, size_t n) {
  auto* bytes = static_cast<unsigned char*>(out);
  if (impl_->compressed) return impl_->read_compressed(bytes, n);
  impl_->file.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(n));
  return static_cast<size_t>(impl_->file.gcount());
}

uint64_t DataStream::skip(uint64_t n) {
  std::vector<unsigned char> scratch(size_t(1) << 18);
  uint64_t skipped = 0;
  while (skipped < n) {
    const size_t want = static_cast<size_t>(std::min<uint64_t>(scratch.size(), n - skipped));
    const size_t got = read(scratch.data(), want);
    skipped += got;
    if (got < want) break;
  }
  return skipped;
}

void DataStream::finish() {
  if (!impl_->compressed || impl_->ended) return;
  skip(std::numeric_limits<uint64_t>::max());
  if (!impl_->ended) {
    throw file_error(impl_->path,
                     "file is truncated (the compressed image data stops before its end)");
  }
}

void read_voxels(const fs::path& path, DataStream& data, uint64_t count, VoxelType type,
                 bool swap_bytes, VoxelSink& sink) {
  const size_t size = voxel_type_size(type);
  const uint64_t needed = count * size;
  std::vector<unsigned char> buffer(size_t(1) << 20);  // a multiple of every element size
  uint64_t done = 0;
  while (done < needed) {
    const size_t want = static_cast<size_t>(std::min<uint64_t>(buffer.size(), needed - done));
    const size_t got = data.read(buffer.data(), want);
    if (got < want) throw truncated_error(path, needed, done + got);
    sink.append(type, buffer.data(), want / size, swap_bytes);
    done += want;
  }
  data.finish();
}

void check_compressed_data(const fs::path& path, DataStream& data, uint64_t skip, uint64_t needed) {
  const uint64_t inflated = data.skip(std::numeric_limits<uint64_t>::max());
  if (inflated < skip + needed)
    throw truncated_error(path, needed, inflated > skip ? inflated - skip : 0);
  data.finish();
}

}  // namespace segmesh::volume_io
