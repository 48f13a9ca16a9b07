#include "segmesh_render/png.hpp"

#include <stdexcept>

#include "segmesh_io/atomic_file.hpp"

// The one definition of stb_image_write in the project.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STBI_WRITE_NO_STDIO
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace segmesh::render {

namespace {
void append(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* bytes = static_cast<const uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}
}  // namespace

std::vector<uint8_t> encode_png(const RgbaImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
    throw std::invalid_argument("encode_png: the pixel buffer does not match the image size");
  }
  bool opaque = true;
  for (size_t i = 3; i < image.rgba.size() && opaque; i += 4) opaque = image.rgba[i] == 255;
  std::vector<uint8_t> rgb;
  const uint8_t* pixels = image.rgba.data();
  int channels = 4;
  if (opaque) {
    rgb.reserve(image.rgba.size() / 4 * 3);
    for (size_t i = 0; i < image.rgba.size(); i += 4) {
      rgb.insert(rgb.end(), image.rgba.begin() + i, image.rgba.begin() + i + 3);
    }
    pixels = rgb.data();
    channels = 3;
  }
  std::vector<uint8_t> png;
  stbi_write_png_compression_level = 9;
  if (!stbi_write_png_to_func(append, &png, image.width, image.height, channels, pixels,
                              image.width * channels)) {
    throw std::runtime_error("encode_png: stb_image_write failed");
  }
  return png;
}

void write_png(const RgbaImage& image, const std::filesystem::path& file) {
  const std::vector<uint8_t> png = encode_png(image);
  AtomicFile out(file);
  out.stream().write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
  out.commit();
}

}  // namespace segmesh::render
