#include "support/pictures.hpp"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace segmesh::test {
namespace {

// Takes ownership of stb_image's result (null when decoding failed).
DecodedPng adopt(stbi_uc* data, int width, int height, int channels_in_file, int components) {
  DecodedPng png;
  if (!data) return png;
  png.width = width;
  png.height = height;
  png.channels_in_file = channels_in_file;
  png.components = components;
  png.pixels.assign(data, data + png.size() * size_t(components));
  stbi_image_free(data);
  return png;
}

}  // namespace

DecodedPng decode_png(const std::vector<uint8_t>& bytes, int components) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data =
      stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &channels, components);
  return adopt(data, w, h, channels, components);
}

DecodedPng read_png(const std::filesystem::path& file, int components) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(file.c_str(), &w, &h, &channels, components);
  return adopt(data, w, h, channels, components);
}

}  // namespace segmesh::test
