#include "segmesh_io/detail/gzip_in_place.hpp"

#include <fcntl.h>
#include <libdeflate.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <limits>
#include <vector>

namespace segmesh::volume_io {

namespace fs = std::filesystem;

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
          const ssize_t n =
              ::pread(fd, copy_.data() + got, copy_.size() - got, static_cast<off_t>(offset + got));
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

}  // namespace

// The fast path for the common .nii.gz (and gzip NRRD): one gzip member whose trailer (ISIZE,
// the inflated size mod 2^32) agrees with what the header claims. Only then is the volume's
// storage touched; libdeflate inflates into it and the sink widens the voxels in place. False,
// with the sink as new, for anything else: the streaming path then decodes and diagnoses.
bool inflate_gzip_in_place(const fs::path& source, uint64_t offset, uint64_t skip, uint64_t count,
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

}  // namespace segmesh::volume_io
