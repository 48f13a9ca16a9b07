// Voxel data plumbing shared by the volume readers. Internal to segmesh_io.
//
// - VoxelType: the file's own element type, with the names Image::voxel_type reports.
// - VoxelSink: converts voxels of any element type, in file order, into the Image's variant:
//   integer files become the narrowest of uint8, int16, uint16, int32 that holds the file's type
//   (values outside int32 are an Error, never wrapped), float files float. A rescale (NIfTI
//   scl_slope/scl_inter, DICOM slope/intercept) keeps an integer file in int32 as long as every
//   rescaled value is a whole number in range, and turns it into float otherwise. Storage is reserved for the whole volume up front (address space only) and filled
//   as voxels arrive, so memory is touched only for data the file really holds.
// - DataStream: the bytes of a file from an offset, raw or inflated (zlib or gzip, several gzip
//   members in a row as bgzip writes them); a corrupt stream is an Error.
// - read_voxel_data: moves a file's voxel data into a sink in one pass, refusing truncated data
//   with the exact byte counts. A gzip stream whose trailer agrees with the header's size is
//   inflated by libdeflate straight into the sink's storage and widened there in place (no
//   second copy of the volume); anything else (other members, zlib streams, a trailer that
//   disagrees, a corrupt or short stream) goes through zlib block by block, which gives the exact
//   diagnosis.
// - check_compressed_data: inflates and counts without keeping anything, so that a compressed
//   file is known to hold what its header claims before anything is allocated (used where a
//   library, not our decoder, reads the voxels afterwards).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/volume.hpp"

namespace segmesh::volume_io {

enum class VoxelType {
  uint8,
  int8,
  uint16,
  int16,
  uint32,
  int32,
  uint64,
  int64,
  float16,
  float32,
  float64
};

std::string_view voxel_type_name(VoxelType type);  // "uint8", ..., "float64"
size_t voxel_type_size(VoxelType type);
bool is_integer(VoxelType type);

struct Rescale {
  double slope = 1;
  double intercept = 0;
  bool identity() const { return slope == 1 && intercept == 0; }
};

class VoxelSink {
 public:
  // The integer stores: a file starts in the narrowest one that holds its type (uint8 in uint8,
  // int8 and int16 in int16, uint16 in uint16, everything else and every rescaled file in int32).
  using IntStore = std::variant<std::vector<uint8_t>, std::vector<int16_t>, std::vector<uint16_t>,
                                std::vector<int32_t>>;

  // Reserves (address space only) `count` voxels. `file_type` decides the store; `rescale`
  // applies to every appended value.
  VoxelSink(std::filesystem::path path, size_t count, VoxelType file_type, Rescale rescale = {});

  // Converts and stores the next `n` values of `type` found at `data` (byte-swapped first when
  // `swap_bytes`). A value the store cannot hold widens it to int32 (or, not a whole number, to
  // float). Throws Error for an integer value outside int32.
  void append(VoxelType type, const void* data, size_t n, bool swap_bytes = false);

  // In-place decoding. Makes room in the voxel storage itself for `prefix` bytes followed by the
  // file bytes of all `count` voxels of `type`, placed at the storage's end so that
  // append_staged() can widen them front to back without overwriting bytes not yet read.
  // Returns where the prefix starts, or nullptr when the sink already holds voxels or `type` is
  // wider than the store (the caller then decodes through append()). Touches the whole storage:
  // call it only once the data are known to be there (e.g. a gzip trailer agrees).
  unsigned char* stage(size_t prefix, VoxelType type);
  // Converts the staged file bytes (as append() would, byte-swapped when `swap_bytes`).
  void append_staged(VoxelType type, bool swap_bytes);
  // Forgets everything appended or staged and frees the storage: the sink is as new.
  void clear();

  // From now on a value outside int32 does not throw at once: the values are still counted, and
  // finish() throws that Error. Readers use it so that a truncated or corrupt stream, and the
  // header checks made after reading, are reported before a bad value, as when the data were
  // counted before they were decoded.
  void defer_value_errors() { defer_ = true; }

  size_t filled() const { return filled_; }

  // The voxels as the Image's volume on `grid`; all `count` values must be appended. Throws the
  // deferred value Error, if any.
  AnyVolume finish(const Grid& grid) &&;

 private:
  void reserve();
  template <class S>
  S* room(std::vector<S>& store, size_t n);
  template <class T>
  void append_typed(const unsigned char* data, size_t n, bool swap_bytes);
  template <class T>
  void convert_block(const T* values, size_t n);
  template <class S, class T>
  size_t convert_ints(std::vector<S>& store, const T* values, size_t n);
  void retire_store();
  void widen_to_int32();
  void promote_to_float();

  std::filesystem::path path_;
  size_t count_;
  size_t filled_ = 0;
  Rescale rescale_;
  VoxelType file_type_;
  bool is_float_;
  IntStore ints_;
  std::vector<float> floats_;
  // stage(): the current store holds the file bytes (sized beyond count_ until finish()) from
  // byte staged_at_ of staged_data_. A store replaced while staged (widened) is kept in retired_
  // until finish(), since the bytes still being converted live in it.
  bool store_staged_ = false;
  unsigned char* staged_data_ = nullptr;
  size_t staged_at_ = 0;
  IntStore retired_;
  bool defer_ = false;
  std::optional<Error> value_error_;
};

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

// Reads `count` voxels of `type` from `data` into `sink`. Throws truncated_error with the exact
// byte counts when the data run out, and finishes the stream.
void read_voxels(const std::filesystem::path& path, DataStream& data, uint64_t count,
                 VoxelType type, bool swap_bytes, VoxelSink& sink);

// The whole voxel data of a file in one pass: `count` voxels of `type` that start `skip` bytes
// into the bytes of `source` from byte `offset` (inflated first when `compressed`), into `sink`.
// Errors name `path` (the header file) for truncated data and `source` for a corrupt stream,
// exactly as read_voxels does; a compressed stream must end properly.
void read_voxel_data(const std::filesystem::path& path, const std::filesystem::path& source,
                     uint64_t offset, bool compressed, uint64_t skip, uint64_t count,
                     VoxelType type, bool swap_bytes, VoxelSink& sink);

// Inflates `data` to its end without keeping it, to learn before allocating whether it holds
// `skip + needed` bytes: throws truncated_error(path, needed, bytes found after `skip`) when it
// does not, and Error when the stream is corrupt or does not end properly.
void check_compressed_data(const std::filesystem::path& path, DataStream& data, uint64_t skip,
                           uint64_t needed);

}  // namespace segmesh::volume_io
