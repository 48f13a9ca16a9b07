#include "segmesh_io/detail/volume_data.hpp"

#include <fcntl.h>
#include <libdeflate.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
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

#include "segmesh/first_touch.hpp"
#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/volume_checks.hpp"

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

// ---------------------------------------------------------------------------------------------
// VoxelSink
//
// Values are converted in blocks of kBlockBytes file bytes, copied (and byte-swapped) into a
// local buffer first: the conversion loops then see no aliasing and vectorise, and in-place
// decoding (stage()) is safe because a block's file bytes are read before its values are written.
// Storage grows block by block inside a reservation of the whole volume, so each block's fresh
// memory is written while it is in cache and never before the file has supplied its data.

namespace {
constexpr size_t kBlockBytes = 16384;
// stage() refuses a prefix larger than this (a NIfTI extension of megabytes): it would stay in
// the volume's capacity. Such files are decoded block by block instead.
constexpr size_t kMaxStagedPrefix = size_t(1) << 20;
}  // namespace

namespace {

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
  // A multiple of every element size, small enough to stay in cache between the read (or
  // inflate) and the conversion.
  std::vector<unsigned char> buffer(size_t(1) << 18);
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

namespace {

// The bytes of a file from `offset` to its end, mapped read-only (read into memory where mapping
// fails). Empty when the file cannot be read: the caller then takes the streaming path, which
// reports the problem.
class FileBytes {
 public:
  FileBytes(const fs::path& path, uint64_t offset) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && uint64_t(st.st_size) > offset) {
      const auto file_size = static_cast<uint64_t>(st.st_size);
      void* map = ::mmap(nullptr, file_size, PROT_READ, MAP_PRIVATE, fd, 0);
      if (map != MAP_FAILED) {
        ::madvise(map, file_size, MADV_SEQUENTIAL);
        map_ = map;
        map_size_ = file_size;
        data_ = static_cast<const unsigned char*>(map) + offset;
        size_ = file_size - offset;
      } else {
        copy_.resize(file_size - offset);
        size_t got = 0;
        while (got < copy_.size()) {
          const ssize_t n = ::pread(fd, copy_.data() + got, copy_.size() - got,
                                    static_cast<off_t>(offset + got));
          if (n <= 0) break;
          got += static_cast<size_t>(n);
        }
        if (got == copy_.size()) {
          data_ = copy_.data();
          size_ = copy_.size();
        }
      }
    }
    ::close(fd);
  }
  ~FileBytes() {
    if (map_) ::munmap(map_, map_size_);
  }
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  const unsigned char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void* map_ = nullptr;
  size_t map_size_ = 0;
  std::vector<unsigned char> copy_;
  const unsigned char* data_ = nullptr;
  size_t size_ = 0;
};

// The fast path for the common .nii.gz (and gzip NRRD): one gzip member whose trailer (ISIZE,
// the inflated size mod 2^32) agrees with what the header claims. Only then is the volume's
// storage touched; libdeflate inflates into it and the sink widens the voxels in place. False,
// with the sink as new, for anything else: the streaming path then decodes and diagnoses.
bool inflate_in_place(const fs::path& source, uint64_t offset, uint64_t skip, uint64_t count,
                      VoxelType type, bool swap_bytes, VoxelSink& sink) {
  const uint64_t total = skip + count * voxel_type_size(type);
  if (total > std::numeric_limits<size_t>::max() / 2) return false;
  const FileBytes in(source, offset);
  const unsigned char* bytes = in.data();
  const size_t size = in.size();
  if (size < 18 || bytes[0] != 0x1f || bytes[1] != 0x8b) return false;
  const uint32_t isize = uint32_t(bytes[size - 4]) | uint32_t(bytes[size - 3]) << 8 |
                         uint32_t(bytes[size - 2]) << 16 | uint32_t(bytes[size - 1]) << 24;
  if (isize != static_cast<uint32_t>(total)) return false;
  unsigned char* room = sink.stage(static_cast<size_t>(skip), type);
  if (!room) return false;

  libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor();
  if (!decompressor) {
    sink.clear();
    return false;
  }
  size_t used = 0, produced = 0;
  const libdeflate_result result = libdeflate_gzip_decompress_ex(
      decompressor, bytes, size, room, static_cast<size_t>(total), &used, &produced);
  libdeflate_free_decompressor(decompressor);
  // Another member after the first (bgzip) must be inflated and checked too: streaming path.
  const bool more = size - used >= 2 && bytes[used] == 0x1f && bytes[used + 1] == 0x8b;
  if (result != LIBDEFLATE_SUCCESS || produced != total || more) {
    sink.clear();
    return false;
  }
  sink.append_staged(type, swap_bytes);
  return true;
}

}  // namespace

void read_voxel_data(const fs::path& path, const fs::path& source, uint64_t offset,
                     bool compressed, uint64_t skip, uint64_t count, VoxelType type,
                     bool swap_bytes, VoxelSink& sink) {
  if (compressed && inflate_in_place(source, offset, skip, count, type, swap_bytes, sink)) return;
  DataStream data(source, offset, compressed);
  if (skip > 0 && data.skip(skip) < skip) {
    throw truncated_error(path, count * voxel_type_size(type), 0);
  }
  read_voxels(path, data, count, type, swap_bytes, sink);
}

}  // namespace segmesh::volume_io
