// Byte order (byte_order.hpp): little- and big-endian loads of known byte patterns at odd
// addresses, stores that read back, and swap_bytes_inplace for every element size a volume has
// (and an odd one).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "segmesh_io/detail/byte_order.hpp"

namespace segmesh {
namespace {

TEST(ByteOrder, LoadsEitherOrderAtAnyAddress) {
  const unsigned char bytes[] = {0xff, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08};
  EXPECT_EQ(load_le<uint16_t>(bytes + 1), 0x0201u);
  EXPECT_EQ(load_be<uint16_t>(bytes + 1), 0x0102u);
  EXPECT_EQ(load_le<uint32_t>(bytes + 1), 0x04030201u);
  EXPECT_EQ(load_be<uint32_t>(bytes + 1), 0x01020304u);
  EXPECT_EQ(load_le<uint64_t>(bytes + 1), 0x0807060504030201ull);
  EXPECT_EQ(load_be<int64_t>(bytes + 1), 0x0102030405060708ll);
  EXPECT_EQ(load_value<uint32_t>(bytes + 1, false), load_le<uint32_t>(bytes + 1));
  EXPECT_EQ(load_value<uint32_t>(bytes + 1, true), load_be<uint32_t>(bytes + 1));
}

TEST(ByteOrder, StoresReadBackAndKeepFloatBits) {
  std::string out = "x";
  append_le<uint32_t>(out, 0x46546C67);  // "glTF"
  EXPECT_EQ(out, "xglTF");
  char buffer[1 + sizeof(float) + sizeof(double)];
  const uint32_t nan_bits = 0x7fa00001;  // a signalling NaN with a payload
  float nan;
  std::memcpy(&nan, &nan_bits, sizeof nan);
  char* p = put_le(buffer + 1, nan);
  p = put_le(p, -2.5);
  EXPECT_EQ(p, buffer + sizeof buffer);
  EXPECT_EQ(load_le<uint32_t>(buffer + 1), nan_bits);
  EXPECT_EQ(load_le<double>(buffer + 1 + sizeof(float)), -2.5);
}

TEST(ByteOrder, SwapsEveryElementInPlace) {
  for (const size_t size : {size_t(1), size_t(2), size_t(3), size_t(4), size_t(8)}) {
    std::vector<unsigned char> data(5 * size);
    for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<unsigned char>(i);
    swap_bytes_inplace(data.data(), 5, size);
    for (size_t e = 0; e < 5; ++e) {
      for (size_t b = 0; b < size; ++b) {
        EXPECT_EQ(data[e * size + b], e * size + (size - 1 - b)) << "size " << size;
      }
    }
  }
}

}  // namespace
}  // namespace segmesh
