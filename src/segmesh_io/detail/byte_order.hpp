// Numbers in a file's byte order, whatever the host's. Internal to segmesh_io: the volume readers
// (NIfTI, MRC and raw NRRD/MetaImage data come in either order) and the binary mesh formats (STL,
// glTF and PLY little-endian, PLY also big-endian).
//
// - load_value reads a T from any address, its bytes reversed first when asked; load_le and
//   load_be read a little- or big-endian T.
// - put_le and append_le write a T little-endian, to a raw cursor or the end of a string.
// - swap_bytes_inplace reverses the bytes of every element of an array (a whole block of voxels).
//
// Guarantees: no alignment is needed (everything goes through memcpy) and the bits of a float are
// kept as they are, NaN payloads included. Cost: a load or store is one move, plus a byte swap when
// the orders differ; swap_bytes_inplace is one pass over the array.
//
// The functions are in namespace segmesh because both halves of the library use them:
// segmesh::volume_io and segmesh::mesh_io code finds them without qualification.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>
#include <string>

namespace segmesh {

// The T stored at p (any alignment), byte-swapped first when swap_bytes.
template <class T>
T load_value(const void* p, bool swap_bytes) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (swap_bytes) std::reverse(bytes, bytes + sizeof(T));
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

template <class T>
T load_le(const void* p) {
  return load_value<T>(p, std::endian::native == std::endian::big);
}

template <class T>
T load_be(const void* p) {
  return load_value<T>(p, std::endian::native == std::endian::little);
}

// Writes `value` little-endian at p; returns the byte after it.
template <class T>
char* put_le(char* p, T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(p, bytes, sizeof(T));
  return p + sizeof(T);
}

template <class T>
void append_le(std::string& out, T value) {
  const size_t at = out.size();
  out.resize(at + sizeof(T));
  put_le(out.data() + at, value);
}

// Reorders bytes within each `size`-byte element of the `count` at `data`, in place.
void swap_bytes_inplace(void* data, size_t count, size_t size);

}  // namespace segmesh
