// VoxelSink: the voxels of a file, in file order, converted into the Image's variant. Internal to
// segmesh_io: every volume reader hands its voxels to one (read_voxel_data.hpp, or volume_itk.hpp
// for what ITK decodes).
//
// Integer files become the narrowest of uint8, int16, uint16, int32 that holds the file's type
// (values outside int32 are an Error, never wrapped), float files float. A rescale (NIfTI
// scl_slope/scl_inter, DICOM slope/intercept) keeps an integer file in int32 as long as every
// rescaled value is a whole number in range, and turns it into float otherwise.
//
// Memory: storage for the whole volume is reserved up front (address space only) and filled as
// voxels arrive, so memory is touched only for data the file really holds; a lying header costs
// no more than the data behind it. stage() instead lends the storage itself to an in-place decoder
// (gzip_in_place.hpp), so a volume is never held twice. Cost: one pass over the values, in blocks
// that stay in cache; a widening copies the values stored so far once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <variant>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/volume.hpp"
#include "segmesh_io/detail/voxel_type.hpp"

namespace segmesh::volume_io {

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

}  // namespace segmesh::volume_io
