// A hash table from neighbourhood keys (dc_neighbourhood_keys.hpp) to values, for one thread:
// open addressing on the key (linear probing, at most half full, grown by rehashing the keys),
// the values in the order they were made. Keys are never 0 (no non-trivial cell has an empty
// neighbourhood).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace segmesh::dc {

template <class Value>
class KeyTable {
 public:
  // The index of the entry for `key` (in the order the entries were made), made by make(Value&)
  // when missing.
  template <class Make>
  uint32_t get(uint64_t key, Make&& make) {
    size_t h = hash(key) & mask_;
    for (; keys_[h] != 0; h = (h + 1) & mask_) {
      if (keys_[h] == key) return index_[h];
    }
    return add(h, key, make);
  }
  const Value& operator[](uint32_t index) const { return values_[index]; }

 private:
  // The new entry for `key` at free slot h (not inlined: get's loop stays small).
  template <class Make>
  __attribute__((noinline)) uint32_t add(size_t h, uint64_t key, Make& make) {
    Value v;
    make(v);
    const auto index = static_cast<uint32_t>(values_.size());
    keys_[h] = key;
    index_[h] = index;
    values_.push_back(v);
    if (2 * values_.size() > keys_.size()) grow();
    return index;
  }

  static size_t hash(uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<size_t>(k);
  }
  void grow() {
    std::vector<uint64_t> keys(2 * keys_.size(), 0);
    std::vector<uint32_t> index(keys.size());
    const size_t mask = keys.size() - 1;
    for (size_t i = 0; i < keys_.size(); ++i) {
      if (keys_[i] == 0) continue;
      size_t h = hash(keys_[i]) & mask;
      while (keys[h] != 0) h = (h + 1) & mask;
      keys[h] = keys_[i];
      index[h] = index_[i];
    }
    keys_.swap(keys);
    index_.swap(index);
    mask_ = mask;
    values_.reserve(keys_.size() / 2);
  }

  // values_ has room for as many entries as the slots take (half of them), so it never moves
  // before the table grows, and its pages are first touched as entries come, not copied onto
  // fresh pages at every doubling.
  static constexpr size_t kInitialSlots = 16384;
  std::vector<uint64_t> keys_ = std::vector<uint64_t>(kInitialSlots, 0);  // 0: empty slot
  std::vector<uint32_t> index_ = std::vector<uint32_t>(kInitialSlots);    // into values_
  std::vector<Value> values_ = reserved(kInitialSlots / 2);
  size_t mask_ = kInitialSlots - 1;
  static std::vector<Value> reserved(size_t n) {
    std::vector<Value> v;
    v.reserve(n);
    return v;
  }
};

}  // namespace segmesh::dc
