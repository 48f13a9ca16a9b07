// Pictures in tests: decoded PNG files (`segmesh render`'s output, the viewer's screenshots, the
// PNG encoder's round trip) and the pixel classes the picture tests count (the implant's red,
// the quality colours' blue and green, luminance). stb_image decodes; its implementation is
// compiled once, in pictures.cpp, so no test file includes it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace segmesh::test {

// 8-bit pixels, top row first, `components` bytes each (3: RGB, 4: RGBA). Empty (width and height
// 0, no pixels) when the input is not a PNG that decodes.
struct DecodedPng {
  int width = 0, height = 0;
  int channels_in_file = 0;  // what the file holds: 3 for RGB, 4 for RGBA, ...
  int components = 0;        // bytes per pixel in `pixels`
  std::vector<uint8_t> pixels;

  size_t size() const { return size_t(width) * size_t(height); }  // pixels
  const uint8_t* at(size_t i) const { return &pixels[size_t(components) * i]; }
  const uint8_t* at(int x, int y) const { return at(size_t(y) * size_t(width) + size_t(x)); }
};

// `bytes` decoded to `components` (1 to 4) bytes per pixel.
DecodedPng decode_png(const std::vector<uint8_t>& bytes, int components);

// The PNG file `file` decoded to `components` bytes per pixel (RGB unless told).
DecodedPng read_png(const std::filesystem::path& file, int components = 3);

// Classes of an RGB(A) pixel, 8 bits per channel, as the picture tests count them.
inline double luminance(const uint8_t* px) {
  return 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
}
// The implant's red (the phantom's plate and screws, shaded).
inline bool red_dominant(const uint8_t* px) {
  return px[0] > 60 && px[0] > 2 * px[1] && px[0] > 2 * px[2];
}
// The quality colours' blue (radii ratio near 0) and green (near 1).
inline bool blue_dominant(const uint8_t* px) {
  return px[2] > px[0] + 40 && px[2] > px[1] + 40;
}
inline bool green_dominant(const uint8_t* px) {
  return px[1] > px[0] + 40 && px[1] > px[2] + 40;
}

}  // namespace segmesh::test
