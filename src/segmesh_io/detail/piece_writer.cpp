#include "segmesh_io/detail/piece_writer.hpp"

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <utility>

namespace segmesh::mesh_io {

char* ChunkBuffer::room(size_t n) {
  if (capacity_ - size_ < n) {
    const size_t capacity = std::max(size_ + n, 2 * capacity_);
    auto grown = std::make_unique_for_overwrite<char[]>(capacity);
    if (size_ > 0) std::memcpy(grown.get(), data_.get(), size_);
    data_ = std::move(grown);
    capacity_ = capacity;
  }
  return data_.get() + size_;
}

void ChunkBuffer::append(std::string_view text) {
  char* p = room(text.size());
  if (!text.empty()) std::memcpy(p, text.data(), text.size());
  commit(p + text.size());
}

void write_pieces(std::ostream& out, size_t count, const PieceFill& fill) {
  if (count == 0) return;
  // Pieces in flight at once: enough to keep every thread busy while one writes. Piece i uses
  // buffer i % tokens: pieces leave the pipeline in order, so when piece i + tokens enters,
  // piece i has been written.
  const size_t tokens =
      2 * static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency())) + 1;
  std::vector<ChunkBuffer> buffers(std::min(tokens, count));
  struct Item {
    size_t index;
    std::string_view bytes;
  };
  size_t next = 0;
  tbb::parallel_pipeline(
      buffers.size(),
      tbb::make_filter<void, size_t>(tbb::filter_mode::serial_in_order,
                                     [&](tbb::flow_control& control) -> size_t {
                                       if (next == count) {
                                         control.stop();
                                         return 0;
                                       }
                                       return next++;
                                     }) &
          tbb::make_filter<size_t, Item>(tbb::filter_mode::parallel,
                                         [&](size_t i) {
                                           ChunkBuffer& buffer = buffers[i % buffers.size()];
                                           buffer.clear();
                                           return Item{i, fill(i, buffer)};
                                         }) &
          tbb::make_filter<Item, void>(tbb::filter_mode::serial_in_order, [&](const Item& item) {
            if (!item.bytes.empty()) {
              out.write(item.bytes.data(), static_cast<std::streamsize>(item.bytes.size()));
            }
          }));
}

void PieceList::text(std::string bytes) {
  if (bytes.empty()) return;
  groups_.push_back(Group{std::move(bytes), nullptr, {}, 0});
  pieces_.push_back(Piece{groups_.size() - 1, 0, 0});
}

void PieceList::bytes(const void* data, size_t size) {
  if (size == 0) return;
  groups_.push_back(Group{{}, static_cast<const char*>(data), {}, 0});
  for (size_t begin = 0; begin < size; begin += kPieceBytes) {
    pieces_.push_back(Piece{groups_.size() - 1, begin, std::min(size, begin + kPieceBytes)});
  }
}

void PieceList::items(size_t count, size_t per_piece,
                      std::function<std::string_view(size_t, size_t, ChunkBuffer&)> format) {
  if (count == 0) return;
  groups_.push_back(Group{{}, nullptr, std::move(format), std::max<size_t>(1, kPieceBytes / per_piece)});
  for (size_t begin = 0; begin < count; begin += per_piece) {
    pieces_.push_back(Piece{groups_.size() - 1, begin, std::min(count, begin + per_piece)});
  }
}

size_t PieceList::estimate(const Piece& piece) const {
  const Group& group = groups_[piece.group];
  if (group.format) return (piece.end - piece.begin) * group.item_bytes;
  if (group.data) return piece.end - piece.begin;
  return group.text.size();
}

void PieceList::write(std::ostream& out) const {
  // Consecutive pieces smaller than a piece together are written as one, so that the cost of a
  // piece (a pass through the pipeline, a write call) is paid per kPieceBytes, not per part.
  std::vector<size_t> first{0};  // each task's first piece
  size_t bytes = 0;
  for (size_t i = 0; i < pieces_.size(); ++i) {
    const size_t size = estimate(pieces_[i]);
    if (i > first.back() && bytes + size > kPieceBytes) {
      first.push_back(i);
      bytes = 0;
    }
    bytes += size;
  }
  first.push_back(pieces_.size());
  const auto fill = [&](const Piece& piece, ChunkBuffer& buffer) -> std::string_view {
    const Group& group = groups_[piece.group];
    if (group.format) return group.format(piece.begin, piece.end, buffer);
    if (group.data) return {group.data + piece.begin, piece.end - piece.begin};
    return group.text;
  };
  write_pieces(out, pieces_.empty() ? 0 : first.size() - 1, [&](size_t t, ChunkBuffer& buffer) -> std::string_view {
    if (first[t + 1] == first[t] + 1) return fill(pieces_[first[t]], buffer);
    for (size_t i = first[t]; i < first[t + 1]; ++i) {
      const Piece& piece = pieces_[i];
      // A format appends to the buffer (room, commit) and returns it all; text and raw memory
      // are copied after what is there.
      if (groups_[piece.group].format) fill(piece, buffer);
      else buffer.append(fill(piece, buffer));
    }
    return buffer.view();
  });
}

}  // namespace segmesh::mesh_io
