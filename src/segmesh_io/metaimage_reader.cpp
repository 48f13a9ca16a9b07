#include "segmesh_io/metaimage_reader.hpp"

#include <itkMetaImageIO.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <fstream>
#include <map>
#include <optional>
#include <string>

#include "segmesh_io/volume_checks.hpp"
#include "segmesh_io/volume_data.hpp"
#include "segmesh_io/volume_itk.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return std::string(text.substr(first, last - first + 1));
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

struct MetaHeader {
  std::map<std::string, std::string> fields;  // lower-case key -> value
  uint64_t data_offset = 0;                   // first byte after the ElementDataFile line

  std::string get(const std::string& key, const std::string& fallback = "") const {
    const auto it = fields.find(key);
    return it == fields.end() ? fallback : it->second;
  }
  bool flag(const std::string& key) const {
    const std::string value = lower(get(key));
    return value == "true" || value == "1";
  }
};

// Reads "Key = Value" lines up to ElementDataFile, which MetaIO requires to be the last field.
MetaHeader parse_header(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  MetaHeader header;
  uint64_t position = 0;
  for (std::string line; std::getline(file, line);) {
    position += line.size() + 1;
    const auto equals = line.find('=');
    if (equals == std::string::npos) {
      if (trim(line).empty()) continue;
      break;
    }
    const std::string key = lower(trim(std::string_view(line).substr(0, equals)));
    const std::string value = trim(std::string_view(line).substr(equals + 1));
    // MetaIO copies field names into 255-byte buffers and values into 255 doubles without
    // checking (fuzz_mha: a fortify abort in MET_InitReadField): longer ones are refused here.
    if (key.size() > 100 || value.size() > 1000) {
      throw file_error(path, "a MetaImage header line is " +
                                 std::to_string(line.size()) +
                                 " characters long (field names are at most 100, values 1000); "
                                 "the header is corrupt");
    }
    header.fields[key] = value;
    if (key == "elementdatafile") {
      header.data_offset = position;
      return header;
    }
    if (position > (1u << 20)) break;
  }
  throw file_error(path, "not a MetaImage file (no ElementDataFile field in its header)");
}

// The integer value of `field` (spelled as in the file format), or `fallback` when absent.
int64_t integer_field(const fs::path& path, const MetaHeader& meta, const std::string& field,
                      int64_t fallback) {
  const auto it = meta.fields.find(lower(field));
  if (it == meta.fields.end()) return fallback;
  const std::string& value = it->second;
  int64_t result = 0;
  const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), result);
  if (ec != std::errc() || end != value.data() + value.size()) {
    throw file_error(path, field + " \"" + value + "\" is not an integer; the header is corrupt");
  }
  return result;
}

std::optional<VoxelType> voxel_type_of(const std::string& element_type) {
  // MetaIO's MET_LONG is 4 bytes; 8-byte integers are MET_LONG_LONG.
  static const std::map<std::string, VoxelType> types = {
      {"MET_UCHAR", VoxelType::uint8},       {"MET_CHAR", VoxelType::int8},
      {"MET_USHORT", VoxelType::uint16},     {"MET_SHORT", VoxelType::int16},
      {"MET_UINT", VoxelType::uint32},       {"MET_INT", VoxelType::int32},
      {"MET_ULONG", VoxelType::uint32},      {"MET_LONG", VoxelType::int32},
      {"MET_ULONG_LONG", VoxelType::uint64}, {"MET_LONG_LONG", VoxelType::int64},
      {"MET_FLOAT", VoxelType::float32},     {"MET_DOUBLE", VoxelType::float64}};
  const auto it = types.find(element_type);
  return it == types.end() ? std::nullopt : std::optional(it->second);
}

}  // namespace

Image read_metaimage(const fs::path& path, const ReadOptions& options) {
  const MetaHeader meta = parse_header(path);
  // MetaIO reads NDims numbers for several fields (NDims squared for TransformMatrix) and hangs
  // on an absurd count (found by fuzz_mha): the count is checked before ITK sees the file.
  if (!meta.fields.count("ndims")) {
    throw file_error(path, "not a MetaImage file (no NDims field in its header)");
  }
  const int64_t ndims = integer_field(path, meta, "NDims", 0);
  if (ndims < 1 || ndims > 8) {
    throw file_error(path, "NDims = " + meta.get("ndims") +
                               " is not a dimension count (1 to 8); the header is corrupt");
  }
  const std::string element_type = meta.get("elementtype");
  const std::optional<VoxelType> type = voxel_type_of(element_type);
  if (!type) {
    throw file_error(path, "ElementType \"" + element_type +
                               "\" is not supported; save the "
                               "volume with an integer or float type");
  }
  if (integer_field(path, meta, "ElementNumberOfChannels", 1) < 1) {
    throw file_error(path, "ElementNumberOfChannels = " + meta.get("elementnumberofchannels") +
                               " is not a channel count; the header is corrupt");
  }
  if (integer_field(path, meta, "ElementNumberOfChannels", 1) > 1) {
    throw file_error(path, "images with " + meta.get("elementnumberofchannels") +
                               " values per voxel are not supported; extract one channel first");
  }
  if (meta.fields.count("binarydata") && !meta.flag("binarydata")) {
    throw file_error(path,
                     "ASCII MetaImage data (BinaryData = False) is not supported; save it "
                     "as binary data");
  }
  const std::string data_file = meta.get("elementdatafile");
  if (data_file.rfind("LIST", 0) == 0 || data_file.find('%') != std::string::npos ||
      data_file.find(' ') != std::string::npos) {
    throw file_error(path, "MetaImage data split over several files (ElementDataFile = " +
                               data_file + ") is not supported; convert it to a single .mha");
  }

  if (lower(data_file) != "local") {  // before ITK opens it (a pipe would block)
    fs::path source = data_file;
    if (source.is_relative()) source = path.parent_path() / source;
    check_data_file(path, source);
  }
  auto io = itk::MetaImageIO::New();
  const ItkHeader header = read_itk_header(*io, path);
  const std::array<int64_t, 3> dims = check_dims(path, header.dims);
  check_voxel_limit(path, dims, options.max_voxels);
  check_grid(path, header.grid, "ElementSpacing");
  if (header.components != 1 || header.component_size != voxel_type_size(*type)) {
    throw file_error(path, "the header is inconsistent (ElementType " + element_type +
                               " does not match what ITK reads); the file is corrupt");
  }

  const uint64_t count = header.grid.voxel_count();
  const uint64_t needed = count * voxel_type_size(*type);
  const bool compressed = meta.flag("compresseddata");
  fs::path source = path;
  uint64_t offset = meta.data_offset;
  if (lower(data_file) != "local") {
    source = fs::path(data_file);
    if (source.is_relative()) source = path.parent_path() / source;
    check_data_file(path, source);
    const int64_t header_size = integer_field(path, meta, "HeaderSize", 0);
    const uint64_t size = size_of_file(source);
    // HeaderSize -1: the data are the file's last bytes.
    offset = header_size >= 0 ? uint64_t(header_size)
                              : (size > needed && !compressed ? size - needed : 0);
  }
  const uint64_t size = size_of_file(source);
  const uint64_t stored = size > offset ? size - offset : 0;
  // Compressed data are counted while they are decoded, into storage that grows with the data.
  check_data_fits(path, needed, stored, compressed);

  const bool big_endian = meta.flag("binarydatabyteordermsb") || meta.flag("elementbyteordermsb");
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  VoxelSink sink(path, count, *type);
  sink.defer_value_errors();  // stream faults first, as when the data were counted first
  read_voxel_data(path, source, offset, compressed, 0, count, *type, swap, sink);
  return Image{
      path.string(), std::string(voxel_type_name(*type)), std::move(sink).finish(header.grid), {}};
}

}  // namespace segmesh::volume_io
