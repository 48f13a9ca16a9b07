// Helpers shared by the volume reader/writer tests: raw bytes in and out of (gzip) files,
// little-endian header patching, and checks on segmesh::Error messages. Their own namespace keeps
// them apart from the mesh tests' helpers of the same names (one test program, one ODR).
#pragma once

#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/image.hpp"

namespace segmesh::volume_test {

using Bytes = std::vector<unsigned char>;

inline Bytes read_bytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

inline void write_bytes(const std::filesystem::path& path, const Bytes& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// The inflated content of a .gz file.
inline Bytes gunzip(const std::filesystem::path& path) {
  Bytes out;
  gzFile file = gzopen(path.string().c_str(), "rb");
  unsigned char buffer[1 << 16];
  for (int n; (n = gzread(file, buffer, sizeof buffer)) > 0;)
    out.insert(out.end(), buffer, buffer + n);
  gzclose(file);
  return out;
}

inline void write_gzip(const std::filesystem::path& path, const Bytes& bytes) {
  gzFile file = gzopen(path.string().c_str(), "wb1");
  gzwrite(file, bytes.data(), unsigned(bytes.size()));
  gzclose(file);
}

// zlib (not gzip) format, as MetaImage stores compressed data.
inline Bytes zlib_compress(const Bytes& bytes) {
  uLongf size = compressBound(uLong(bytes.size()));
  Bytes out(size);
  compress(out.data(), &size, bytes.data(), uLong(bytes.size()));
  out.resize(size);
  return out;
}

template <class T>
void put(Bytes& bytes, size_t offset, T value) {
  if (bytes.size() < offset + sizeof(T)) bytes.resize(offset + sizeof(T));
  std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

template <class T>
T get(const Bytes& bytes, size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

inline void append(Bytes& bytes, const std::string& text) {
  bytes.insert(bytes.end(), text.begin(), text.end());
}

// Runs `action`, expects a segmesh::Error whose one-line message contains every `part`, and
// returns the message.
inline std::string expect_error(const std::function<void()>& action,
                                std::initializer_list<std::string> parts) {
  try {
    action();
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message: " << message << "\nmissing: " << part;
    }
    return message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected segmesh::Error, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected segmesh::Error, nothing was thrown";
  return {};
}

inline std::set<int32_t> label_set(const LabelVolume& volume) {
  return std::set<int32_t>(volume.voxels.begin(), volume.voxels.end());
}

// A minimal NIfTI-1 single-file header (348 bytes + 4 extension bytes); RAS affine = diag(pixdim)
// via sform_code 1.
inline Bytes nifti1_header(std::vector<int16_t> dims, int16_t datatype, int16_t bitpix,
                           std::vector<float> pixdim = {1, 1, 1}) {
  Bytes h(352, 0);
  put<int32_t>(h, 0, 348);
  put<int16_t>(h, 40, int16_t(dims.size()));
  for (size_t i = 0; i < dims.size(); ++i) put<int16_t>(h, 42 + 2 * i, dims[i]);
  put<int16_t>(h, 70, datatype);
  put<int16_t>(h, 72, bitpix);
  put<float>(h, 76, 1.0f);
  for (size_t i = 0; i < pixdim.size(); ++i) put<float>(h, 80 + 4 * i, pixdim[i]);
  put<float>(h, 108, 352.0f);
  put<float>(h, 112, 1.0f);
  put<int16_t>(h, 254, 1);  // sform_code
  for (int r = 0; r < 3; ++r)
    put<float>(h, 280 + 16 * r + 4 * r, r < int(pixdim.size()) ? pixdim[r] : 1.0f);
  std::memcpy(h.data() + 344, "n+1\0", 4);
  return h;
}

}  // namespace segmesh::volume_test
