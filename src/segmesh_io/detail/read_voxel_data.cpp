#include "segmesh_io/detail/read_voxel_data.hpp"

#include <algorithm>
#include <vector>

#include "segmesh_io/detail/data_stream.hpp"
#include "segmesh_io/detail/gzip_in_place.hpp"
#include "segmesh_io/detail/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

// Reads `count` voxels of `type` from `data` into `sink`. Throws truncated_error with the exact
// byte counts when the data run out, and finishes the stream.
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

}  // namespace

void read_voxel_data(const fs::path& path, const fs::path& source, uint64_t offset, bool compressed,
                     uint64_t skip, uint64_t count, VoxelType type, bool swap_bytes,
                     VoxelSink& sink) {
  if (compressed && inflate_gzip_in_place(source, offset, skip, count, type, swap_bytes, sink)) {
    return;
  }
  DataStream data(source, offset, compressed);
  if (skip > 0 && data.skip(skip) < skip) {
    throw truncated_error(path, count * voxel_type_size(type), 0);
  }
  read_voxels(path, data, count, type, swap_bytes, sink);
}

}  // namespace segmesh::volume_io
