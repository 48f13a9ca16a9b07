// Decoded PNG pictures for the tests that check what a rendering shows (`segmesh render`, the
// viewer's screenshots, the PNG encoder's round trip). stb_image decodes them; its implementation
// is compiled once, in decoded_png.cpp, so no test file includes it.
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

// The implant's red (the phantom's plate and screws, shaded), as the picture tests count it.
inline bool is_red(const uint8_t* rgb) {
  return rgb[0] > 60 && rgb[0] > 2 * rgb[1] && rgb[0] > 2 * rgb[2];
}

}  // namespace segmesh::test
