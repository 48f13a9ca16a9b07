// PNG encoding and atomic writing: what goes in comes back out of a decoder, and a write that
// cannot happen leaves nothing behind.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "segmesh/error.hpp"
#include "segmesh_render/png.hpp"
#include "support/pictures.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

using namespace segmesh::render;

RgbaImage pattern(int w, int h, bool translucent) {
  RgbaImage img{w, h, std::vector<uint8_t>(size_t(w) * h * 4)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &img.rgba[4 * (size_t(y) * w + x)];
      p[0] = uint8_t(x * 7), p[1] = uint8_t(y * 13), p[2] = uint8_t(x ^ y);
      p[3] = translucent ? uint8_t(255 - x) : 255;
    }
  return img;
}

TEST(Png, RoundTripsRgbAndRgba) {
  for (bool translucent : {false, true}) {
    const RgbaImage img = pattern(37, 23, translucent);
    const std::vector<uint8_t> png = encode_png(img);
    const test::DecodedPng back = test::decode_png(png, 4);
    ASSERT_FALSE(back.pixels.empty());
    EXPECT_EQ(back.width, 37);
    EXPECT_EQ(back.height, 23);
    EXPECT_EQ(back.channels_in_file, translucent ? 4 : 3);  // opaque pictures drop the alpha
    EXPECT_EQ(back.pixels, img.rgba);
  }
  EXPECT_THROW(encode_png(RgbaImage{4, 4, std::vector<uint8_t>(10)}), std::invalid_argument);
}

TEST(Png, WritesAtomically) {
  const auto dir = test::scratch_dir("png_write");
  write_png(pattern(8, 8, false), dir / "a.png");
  std::ifstream in(dir / "a.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  EXPECT_THROW(write_png(pattern(8, 8, false), dir / "missing" / "b.png"), Error);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "a.png");
    ++files;
  }
  EXPECT_EQ(files, 1);
}

}  // namespace
}  // namespace segmesh
