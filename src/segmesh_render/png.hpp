// RgbaImage (8-bit RGBA pixels, top row first) and PNG encoding with stb_image_write.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace segmesh::render {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes, rows top to bottom

  const uint8_t* pixel(int x, int y) const { return rgba.data() + 4 * (size_t(y) * width + x); }
};

// The image as PNG bytes; RGB when every pixel is opaque (smaller files), RGBA otherwise.
std::vector<uint8_t> encode_png(const RgbaImage& image);

// Writes the image as a PNG file atomically (a temporary file renamed when complete). Throws
// segmesh::Error naming the file when its folder is missing or the disk refuses it.
void write_png(const RgbaImage& image, const std::filesystem::path& file);

}  // namespace segmesh::render
