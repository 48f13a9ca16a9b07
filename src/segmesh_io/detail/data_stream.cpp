#include "segmesh_io/detail/data_stream.hpp"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "segmesh_io/detail/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

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

void check_compressed_data(const fs::path& path, DataStream& data, uint64_t skip, uint64_t needed) {
  const uint64_t inflated = data.skip(std::numeric_limits<uint64_t>::max());
  if (inflated < skip + needed)
    throw truncated_error(path, needed, inflated > skip ? inflated - skip : 0);
  data.finish();
}

}  // namespace segmesh::volume_io
