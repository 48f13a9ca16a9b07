#include "segmesh_io/metaimage_reader.hpp"

#include <itkMetaImageIO.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "segmesh_io/detail/read_voxel_data.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/volume_itk.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

// A header value as it may appear in a one-line message: control and non-ASCII bytes become '?',
// long values are cut.
std::string printable(std::string_view text) {
  std::string shown;
  for (const char c : text.substr(0, 40)) {
    const auto byte = static_cast<unsigned char>(c);
    shown += byte < 0x20 || byte >= 0x7f ? '?' : c;
  }
  if (text.size() > 40) shown += "...";
  return shown;
}

// The fields MetaIO (ITK 5.2: metaObject.cxx, metaImage.cxx) registers for an image header, and how
// it reads their values. Numbers are read with `istream >> double`, as many as the field has; the
// count of most comes from NDims, read earlier in the same pass. Every other name is kept as text.
enum class Count { text, one, four, ndims, ndims_squared };
struct MetaField {
  std::string_view name;
  Count count;
  bool whole;  // MetaIO casts the numbers to an integer type
};
constexpr MetaField kMetaFields[] = {
    {"Comment", Count::text, false},
    {"AcquisitionDate", Count::text, false},
    {"ObjectType", Count::text, false},
    {"ObjectSubType", Count::text, false},
    {"NDims", Count::one, true},
    {"Name", Count::text, false},
    {"ID", Count::one, true},
    {"ParentID", Count::one, true},
    {"CompressedData", Count::text, false},
    {"CompressedDataSize", Count::one, true},
    {"BinaryData", Count::text, false},
    {"ElementByteOrderMSB", Count::text, false},
    {"BinaryDataByteOrderMSB", Count::text, false},
    {"Color", Count::four, false},
    {"Position", Count::ndims, false},
    {"Origin", Count::ndims, false},
    {"Offset", Count::ndims, false},
    {"TransformMatrix", Count::ndims_squared, false},
    {"Rotation", Count::ndims_squared, false},
    {"Orientation", Count::ndims_squared, false},
    {"CenterOfRotation", Count::ndims, false},
    {"DistanceUnits", Count::text, false},
    {"AnatomicalOrientation", Count::text, false},
    {"ElementSpacing", Count::ndims, false},
    {"DimSize", Count::ndims, true},
    {"HeaderSize", Count::one, true},
    {"Modality", Count::text, false},
    {"ImagePosition", Count::ndims, false},
    {"SequenceID", Count::ndims, true},
    {"ElementMin", Count::one, false},
    {"ElementMax", Count::one, false},
    {"ElementNumberOfChannels", Count::one, true},
    {"ElementSize", Count::ndims, false},
    {"ElementNBits", Count::one, true},
    {"ElementToIntensityFunctionSlope", Count::one, false},
    {"ElementToIntensityFunctionOffset", Count::one, false},
    {"ElementType", Count::text, false},
    {"ElementDataFile", Count::text, false},
};

const MetaField* find_field(std::string_view name) {
  for (const MetaField& field : kMetaFields)
    if (field.name == name) return &field;
  return nullptr;
}

struct MetaHeader {
  // Fields in file order, named exactly as in the file (MetaIO compares names case-sensitively).
  std::vector<std::pair<std::string, std::string>> fields;
  uint64_t data_offset = 0;  // first byte after the ElementDataFile line

  bool has(std::string_view key) const {
    return std::any_of(fields.begin(), fields.end(), [&](const auto& f) { return f.first == key; });
  }
  std::string get(std::string_view key, const std::string& fallback = "") const {
    for (const auto& [name, value] : fields)
      if (name == key) return value;
    return fallback;
  }
  bool flag(std::string_view key) const {
    const std::string value = lower(get(key));
    return value == "true" || value == "1";
  }
};

// Reads "Name = Value" lines up to ElementDataFile, which MetaIO requires to be the last field.
// MetaIO's own reading (MET_Read in metaUtils.cxx) is mirrored where it decides which field a
// line is: leading white space is skipped, the name ends at the first '=' or ':' (both are
// separators), trailing blanks are cut, and the name is compared case-sensitively; the value
// starts after all the separators and blanks that follow. A header that MetaIO could read
// differently from these lines (a field name in another case or given twice, a control
// character in a name) is refused: the checks below are only worth anything if they see the
// fields MetaIO will use (fuzz_mha: "NDIms = 2" passed the NDims check while MetaIO took 1e22
// from "NDims" and looped on it).
MetaHeader parse_header(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  MetaHeader header;
  uint64_t position = 0;
  for (std::string line; std::getline(file, line);) {
    position += line.size() + 1;
    const std::string_view text(line);
    const auto first = text.find_first_not_of(" \t\r\v\f");
    if (first == std::string_view::npos) continue;
    const auto separator = text.find_first_of("=:", first);
    if (separator == std::string_view::npos) break;
    std::string_view name = text.substr(first, separator - first);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.remove_suffix(1);
    auto value_start = text.find_first_not_of("=: \t", separator);
    if (value_start == std::string_view::npos) value_start = text.size();
    const std::string value(trim(text.substr(value_start)));
    // MetaIO copies field names into 255-byte buffers and values into 255 doubles without
    // checking (fuzz_mha: a fortify abort in MET_InitReadField): longer ones are refused here.
    if (name.size() > 100 || value.size() > 1000) {
      throw file_error(path, "a MetaImage header line is " + std::to_string(line.size()) +
                                 " characters long (field names are at most 100, values 1000); "
                                 "the header is corrupt");
    }
    if (std::any_of(name.begin(), name.end(),
                    [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; })) {
      throw file_error(path, "the MetaImage header field name \"" + printable(name) +
                                 "\" holds a control character; the header is corrupt");
    }
    header.fields.emplace_back(name, value);
    if (name == "ElementDataFile") {
      header.data_offset = position;
      break;
    }
    if (position > (1u << 20)) break;
  }
  if (header.data_offset == 0) {
    throw file_error(path, "not a MetaImage file (no ElementDataFile field in its header)");
  }
  for (auto it = header.fields.begin(); it != header.fields.end(); ++it) {
    const std::string& name = it->first;
    if (!find_field(name)) {
      for (const MetaField& field : kMetaFields) {
        if (lower(std::string(field.name)) == lower(name)) {
          throw file_error(path, "the MetaImage header field \"" + printable(name) +
                                     "\" must be spelled \"" + std::string(field.name) +
                                     "\" (MetaIO ignores it otherwise); the header is corrupt");
        }
      }
    } else if (std::any_of(header.fields.begin(), it,
                           [&](const auto& earlier) { return earlier.first == name; })) {
      throw file_error(path,
                       "the MetaImage header gives " + name + " twice; the header is corrupt");
    }
  }
  return header;
}

// A number as `istream >> double` reads it whole and std::from_chars can convert it: an optional
// sign, digits with at most one decimal point, an optional exponent ("inf", "nan" and hexadecimal
// are not numbers to MetaIO). `whole`: digits only.
std::optional<double> metaio_number(std::string_view token, bool whole) {
  size_t i = 0;
  const auto digits = [&] {
    const size_t begin = i;
    while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i]))) ++i;
    return i - begin;
  };
  if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
  size_t mantissa = digits();
  if (!whole && i < token.size() && token[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) return std::nullopt;
  if (!whole && i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
    ++i;
    if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
    if (digits() == 0) return std::nullopt;
  }
  if (i != token.size()) return std::nullopt;
  if (token.front() == '+') token.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// The white-space separated numbers of `value`, or nullopt when one is not a number.
std::optional<std::vector<double>> parse_numbers(std::string_view value, bool whole) {
  std::vector<double> numbers;
  size_t i = 0;
  while (true) {
    i = value.find_first_not_of(" \t\r\v\f", i);
    if (i == std::string_view::npos) return numbers;
    const size_t end = std::min(value.find_first_of(" \t\r\v\f", i), value.size());
    const std::optional<double> number = metaio_number(value.substr(i, end - i), whole);
    if (!number) return std::nullopt;
    numbers.push_back(*number);
    i = end;
  }
}

// Checks every field MetaIO reads as numbers before ITK parses the header: MetaIO reads as many
// numbers as NDims (or NDims squared) says, skipping line ends, into fixed arrays, so a field with
// fewer numbers than that swallows the next lines, an NDims MetaIO reads as 1e22 or -1 makes it
// read 2^64 numbers (a hang, found by fuzz_mha), and text where a number belongs stops the stream.
// Each field must hold exactly its numbers, on its own line.
void check_numbers(const fs::path& path, const MetaHeader& meta) {
  if (!meta.has("NDims")) {
    throw file_error(path, "not a MetaImage file (no NDims field in its header)");
  }
  int64_t ndims = 0;  // 0 until the NDims line
  for (const auto& [name, value] : meta.fields) {
    const MetaField* field = find_field(name);
    if (!field || field->count == Count::text) continue;
    if (name == "NDims") {
      const std::optional<std::vector<double>> numbers = parse_numbers(value, true);
      if (!numbers || numbers->size() != 1) {
        throw file_error(
            path, "NDims \"" + printable(value) + "\" is not an integer; the header is corrupt");
      }
      if (numbers->front() < 1 || numbers->front() > 8) {
        throw file_error(path, "NDims = " + printable(value) +
                                   " is not a dimension count (1 to 8); the header is corrupt");
      }
      ndims = static_cast<int64_t>(numbers->front());
      continue;
    }
    const bool per_dimension = field->count == Count::ndims || field->count == Count::ndims_squared;
    if (per_dimension && ndims == 0) {  // MetaIO refuses this too, after a message on stderr
      throw file_error(path, std::string(name) +
                                 " comes before NDims in the MetaImage header; "
                                 "the header is corrupt");
    }
    size_t count = 1;
    std::string what = field->whole ? "a whole number" : "a number";
    const std::string plural = field->whole ? " whole numbers" : " numbers";
    if (field->count == Count::four) {
      count = 4;
      what = "4" + plural;
    } else if (field->count == Count::ndims) {
      count = size_t(ndims);
      what = std::to_string(count) + plural +
             " (one per dimension, NDims = " + std::to_string(ndims) + ")";
    } else if (field->count == Count::ndims_squared) {
      count = size_t(ndims * ndims);
      what = std::to_string(count) + plural + " (a " + std::to_string(ndims) + "x" +
             std::to_string(ndims) + " matrix, NDims = " + std::to_string(ndims) + ")";
    }
    const std::optional<std::vector<double>> numbers = parse_numbers(value, field->whole);
    if (!numbers || numbers->size() != count) {
      throw file_error(path, std::string(name) + " = \"" + printable(value) + "\" is not " + what +
                                 "; the header is corrupt");
    }
    // MetaIO casts whole numbers to int (CompressedDataSize: unsigned 64-bit).
    const double low = name == "CompressedDataSize" ? 0 : -2147483648.0;
    const double high = name == "CompressedDataSize" ? 9.2e18 : 2147483647.0;
    for (const double number : *numbers) {
      if (field->whole && (number < low || number > high)) {
        throw file_error(path, std::string(name) + " = " + printable(value) +
                                   " is out of range; the header is corrupt");
      }
      if (name == "DimSize" && number < 1) {
        throw file_error(path, "DimSize = " + printable(value) +
                                   ": every size must be at least 1; the header is corrupt");
      }
    }
    // MetaIO keeps SequenceID in 4 floats but copies NDims of them.
    if (name == "SequenceID" && ndims > 4) {
      throw file_error(path, "SequenceID with NDims = " + std::to_string(ndims) +
                                 " (at most 4) is not supported; remove it from the header");
    }
  }
}

// The whole-number value of `field`, or `fallback` when absent (check_numbers has vetted it).
int64_t integer_field(const MetaHeader& meta, std::string_view field, int64_t fallback) {
  if (!meta.has(field)) return fallback;
  const std::optional<std::vector<double>> numbers = parse_numbers(meta.get(field), true);
  return numbers && numbers->size() == 1 ? static_cast<int64_t>(numbers->front()) : fallback;
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
  check_numbers(path, meta);
  const std::string element_type = meta.get("ElementType");
  const std::optional<VoxelType> type = voxel_type_of(element_type);
  if (!type) {
    throw file_error(path, "ElementType \"" + printable(element_type) +
                               "\" is not supported; save the "
                               "volume with an integer or float type");
  }
  if (integer_field(meta, "ElementNumberOfChannels", 1) < 1) {
    throw file_error(path, "ElementNumberOfChannels = " + meta.get("ElementNumberOfChannels") +
                               " is not a channel count; the header is corrupt");
  }
  if (integer_field(meta, "ElementNumberOfChannels", 1) > 1) {
    throw file_error(path, "images with " + meta.get("ElementNumberOfChannels") +
                               " values per voxel are not supported; extract one channel first");
  }
  if (meta.has("BinaryData") && !meta.flag("BinaryData")) {
    throw file_error(path,
                     "ASCII MetaImage data (BinaryData = False) is not supported; save it "
                     "as binary data");
  }
  const std::string data_file = meta.get("ElementDataFile");
  if (data_file.rfind("LIST", 0) == 0 || data_file.find('%') != std::string::npos ||
      data_file.find(' ') != std::string::npos) {
    throw file_error(path, "MetaImage data split over several files (ElementDataFile = " +
                               data_file + ") is not supported; convert it to a single .mha");
  }

  // A detached data file is checked before ITK opens it (a pipe would block).
  const bool detached = lower(data_file) != "local";
  const fs::path source =
      detached ? detached_data_file(path, data_file, options.allow_external_data) : path;
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
  const bool compressed = meta.flag("CompressedData");
  uint64_t offset = meta.data_offset;
  if (detached) {
    const int64_t header_size = integer_field(meta, "HeaderSize", 0);
    const uint64_t size = size_of_file(source);
    // HeaderSize -1: the data are the file's last bytes.
    offset = header_size >= 0 ? uint64_t(header_size)
                              : (size > needed && !compressed ? size - needed : 0);
  }
  const uint64_t size = size_of_file(source);
  const uint64_t stored = size > offset ? size - offset : 0;
  // Compressed data are counted while they are decoded, into storage that grows with the data.
  check_data_fits(path, needed, stored, compressed);

  const bool big_endian = meta.flag("BinaryDataByteOrderMSB") || meta.flag("ElementByteOrderMSB");
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  VoxelSink sink(path, count, *type);
  sink.defer_value_errors();  // stream faults first, as when the data were counted first
  read_voxel_data(path, source, offset, compressed, 0, count, *type, swap, sink);
  return Image{
      path.string(), std::string(voxel_type_name(*type)), std::move(sink).finish(header.grid), {}};
}

}  // namespace segmesh::volume_io
