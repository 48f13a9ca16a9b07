#include "segmesh_io/detail/gzip_in_place.hpp"

#include <libdeflate.h>

#include <limits>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mapped_file.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

bool inflate_gzip_in_place(const fs::path& source, uint64_t offset, uint64_t skip, uint64_t count,
                           VoxelType type, bool swap_bytes, VoxelSink& sink) {
  const uint64_t total = skip + count * voxel_type_size(type);
  if (total > std::numeric_limits<size_t>::max() / 2) return false;
  const MappedFile in(source, offset);  // not opened: empty, the streaming path reports why
  in.advise_sequential();
  const unsigned char* bytes = in.data();
  const size_t size = in.size();
  if (size < 18 || bytes[0] != 0x1f || bytes[1] != 0x8b) return false;
  // ISIZE, the last 4 bytes: the inflated size mod 2^32.
  if (load_le<uint32_t>(bytes + size - 4) != static_cast<uint32_t>(total)) return false;
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
