// DataStream: the bytes of a file from an offset, raw or inflated through zlib (zlib or gzip
// streams, several gzip members in a row as bgzip writes them). Internal to segmesh_io: the
// readers read headers with it, and read_voxel_data.hpp streams voxels through it whenever the
// one-call gzip path does not apply.
//
// Guarantees: a corrupt stream is an Error naming the file; finish() refuses a stream that stops
// before its end (a member cut short, a wrong checksum), so a truncated file is never read as a
// shorter one. Anything after the last gzip member is ignored, as gzip does. Cost: the file is
// read in 256 KiB blocks and inflated as it is read; nothing of the data is kept.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>

namespace segmesh::volume_io {

class DataStream {
 public:
  // The bytes of `path` from byte `offset`, inflated when `compressed`.
  DataStream(const std::filesystem::path& path, uint64_t offset, bool compressed);
  ~DataStream();
  DataStream(const DataStream&) = delete;
  DataStream& operator=(const DataStream&) = delete;

  // Reads up to n bytes; fewer only at the end of the data.
  size_t read(void* out, size_t n);
  // Skips up to n bytes of (inflated) data; returns how many were skipped.
  uint64_t skip(uint64_t n);
  // For compressed data: reads to the end and throws Error unless the stream ends properly
  // (all members complete, checksums correct). No-op for raw data.
  void finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Inflates `data` to its end without keeping it, to learn before allocating whether it holds
// `skip + needed` bytes: throws truncated_error(path, needed, bytes found after `skip`) when it
// does not, and Error when the stream is corrupt or does not end properly. For data a library,
// not our decoder, reads afterwards (NRRD encodings ITK decodes).
void check_compressed_data(const std::filesystem::path& path, DataStream& data, uint64_t skip,
                           uint64_t needed);

}  // namespace segmesh::volume_io
