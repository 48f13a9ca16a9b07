// MappedFile: a regular file mapped read-only, from an offset to its end. Internal to segmesh_io:
// the one-call gzip path inflates from it (gzip_in_place.hpp) and the DICOM check walks it
// (dicom_file_check.hpp).
//
// Why: both read a file once from memory without copying it; the kernel pages it in as it is
// read. Guarantees: only a regular file is mapped (a device or a pipe has no end to map to); when
// the file cannot be opened, is not regular or cannot be mapped, opened() is false and error()
// holds the errno (EINVAL for a file that is not regular). An empty file, or an offset at or past
// the end, gives an empty view of an opened file. Cost: one mmap; nothing is read up front.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace segmesh::volume_io {

class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& path, uint64_t offset = 0);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  bool opened() const { return opened_; }
  int error() const { return error_; }  // errno when not opened
  // The bytes from the offset to the end of the file; nullptr and 0 when there are none.
  const unsigned char* data() const { return data_; }
  size_t size() const { return size_; }

  // Tells the kernel the bytes will be read front to back (more read-ahead).
  void advise_sequential() const;

 private:
  void* map_ = nullptr;
  size_t map_size_ = 0;
  const unsigned char* data_ = nullptr;
  size_t size_ = 0;
  bool opened_ = false;
  int error_ = 0;
};

}  // namespace segmesh::volume_io
