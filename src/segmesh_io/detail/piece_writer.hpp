// How the mesh writers (stl_writer, ply_writer, obj_writer, gltf_writer) produce a file: as pieces
// formatted in parallel on oneTBB's threads and written to the stream in order. Internal to
// segmesh_io.
//
// Why: a mesh of millions of triangles formats on every thread, and the file is never built in
// memory. Guarantees: pieces reach the stream in order, so the output is the same for any thread
// count; a piece may also point at memory that outlives the write (a mesh's own arrays), which is
// written as it is. Cost: each piece is formatted once; memory is a small ring of reused buffers
// (two per thread, plus one) of about kPieceBytes each.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace segmesh::mesh_io {

// A reusable byte buffer that writers fill through a raw cursor: room(n) guarantees n writable
// bytes at the end, commit(p) makes everything up to p part of the contents.
class ChunkBuffer {
 public:
  char* room(size_t n);
  void commit(char* end) { size_ = static_cast<size_t>(end - data_.get()); }
  void append(std::string_view text);
  void clear() { size_ = 0; }
  std::string_view view() const { return {data_.get(), size_}; }

 private:
  std::unique_ptr<char[]> data_;
  size_t capacity_ = 0;
  size_t size_ = 0;
};

// How writers produce a file: as `count` pieces written to `out` in order. fill(i, buffer)
// returns piece i's bytes, either formatted into `buffer` (handed over empty) or pointing at
// memory that outlives the call (a mesh's own arrays). Pieces are filled in parallel on oneTBB's
// threads while earlier ones are being written, through a small ring of reused buffers, so the
// file is never built in memory and the output is the same for any thread count. Aim for pieces
// of about kPieceBytes.
inline constexpr size_t kPieceBytes = size_t(1) << 20;
using PieceFill = std::function<std::string_view(size_t, ChunkBuffer&)>;
void write_pieces(std::ostream& out, size_t count, const PieceFill& fill);

// A list of pieces built part by part: text known in advance, raw memory, or ranges of `items`
// things formatted by a function, split into pieces of at most `per_piece` items (so one item
// is taken to be about kPieceBytes / per_piece bytes). A format appends to the buffer it is given
// (room, commit) and returns the buffer's view: consecutive small pieces (the parts of a
// many-part scene) are formatted into one buffer and written together, so the cost per piece
// is paid about once per kPieceBytes, not once per part.
class PieceList {
 public:
  void text(std::string bytes);
  void bytes(const void* data, size_t size);  // raw memory, written as it is
  void items(size_t count, size_t per_piece,
             std::function<std::string_view(size_t begin, size_t end, ChunkBuffer&)> format);
  // `count` records of `record_bytes` each (a vertex, a face), in pieces of about kPieceBytes:
  // put(i, p) writes record i at p and returns the byte after it.
  template <class Put>
  void records(size_t count, size_t record_bytes, Put put) {
    items(count, std::max<size_t>(1, kPieceBytes / record_bytes),
          [put, record_bytes](size_t begin, size_t end, ChunkBuffer& buffer) {
            char* p = buffer.room((end - begin) * record_bytes);
            for (size_t i = begin; i < end; ++i) p = put(i, p);
            buffer.commit(p);
            return buffer.view();
          });
  }
  void write(std::ostream& out) const;

 private:
  struct Piece {
    size_t group;
    size_t begin, end;
  };
  struct Group {
    std::string text;
    const char* data = nullptr;
    std::function<std::string_view(size_t, size_t, ChunkBuffer&)> format;
    size_t item_bytes;  // a formatted item's size, about
  };
  size_t estimate(const Piece& piece) const;  // bytes, about
  std::vector<Group> groups_;
  std::vector<Piece> pieces_;
};

}  // namespace segmesh::mesh_io
