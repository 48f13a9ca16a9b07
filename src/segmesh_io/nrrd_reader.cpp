#include "segmesh_io/nrrd_reader.hpp"

#include <itkMetaDataObject.h>
#include <itkNrrdImageIO.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include "segmesh_io/detail/data_stream.hpp"
#include "segmesh_io/detail/read_voxel_data.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/volume_itk.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

// Where a NRRD's data bytes are and how they are encoded (the fields ITK does not report).
struct NrrdLayout {
  std::string encoding = "raw";
  std::string data_file;  // empty: the data follow the header in the same file
  std::string endian;     // "little", "big" or empty
  int64_t line_skip = 0;
  int64_t byte_skip = 0;
  uint64_t header_end = 0;  // first byte after the blank line ending an attached header
};

NrrdLayout scan_layout(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  NrrdLayout layout;
  std::string line;
  if (!std::getline(file, line) || line.rfind("NRRD", 0) != 0) {
    throw file_error(path, "not a NRRD file (it does not start with \"NRRD\")");
  }
  uint64_t position = line.size() + 1;
  bool blank_line = false;
  while (std::getline(file, line)) {
    position += line.size() + 1;
    const std::string text(trim(line));
    if (text.empty()) {
      blank_line = true;
      break;
    }
    if (text[0] == '#') continue;
    const auto colon = text.find(':');
    if (colon == std::string::npos || (colon + 1 < text.size() && text[colon + 1] == '=')) continue;
    std::string field = lower(text.substr(0, colon));
    field.erase(std::remove(field.begin(), field.end(), ' '), field.end());
    const std::string value(trim(std::string_view(text).substr(colon + 1)));
    try {
      if (field == "encoding") layout.encoding = value;
      if (field == "datafile") layout.data_file = value;
      if (field == "endian") {
        layout.endian = lower(value);
      }
      if (field == "lineskip") layout.line_skip = std::stoll(value);
      if (field == "byteskip") layout.byte_skip = std::stoll(value);
    } catch (const std::exception&) {
      throw file_error(path, "the header field \"" + field + "\" has the invalid value \"" + value +
                                 "\"; the file is corrupt");
    }
  }
  layout.header_end = position;
  if (layout.data_file.empty() && !blank_line) {
    throw file_error(path, "the NRRD header names no data file and has no data after it");
  }
  return layout;
}

// "data file: LIST" and %-patterns name several detached files.
bool names_several_files(const std::string& data_file) {
  return data_file.rfind("LIST", 0) == 0 || data_file.find('%') != std::string::npos;
}

// Where raw or gzip data in this file or one detached file begin.
struct DataPlace {
  fs::path source;
  uint64_t offset = 0;  // in the file
  bool compressed = false;
  uint64_t skip = 0;  // after inflating
};

// Refuses, before anything is allocated, data that cannot hold `needed` bytes. Checks raw and
// gzip data in this file or one detached file, and returns where they are (we decode those);
// other encodings and multi-file data are left to ITK, which refuses short data too.
std::optional<DataPlace> check_nrrd_data(const fs::path& path, const NrrdLayout& layout,
                                         uint64_t needed, bool allow_external) {
  const bool gzip = layout.encoding == "gzip" || layout.encoding == "gz";
  if (!(gzip || layout.encoding == "raw")) return std::nullopt;
  if (names_several_files(layout.data_file)) return std::nullopt;

  fs::path source = path;
  uint64_t offset = layout.header_end;
  if (!layout.data_file.empty()) {
    source = detached_data_file(path, layout.data_file, allow_external);
    offset = 0;
  }
  if (layout.line_skip > 0) {
    std::ifstream file(source, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(offset));
    std::string skipped;
    for (int64_t i = 0; i < layout.line_skip && std::getline(file, skipped); ++i) {
      offset += skipped.size() + 1;
    }
  }
  const uint64_t size = size_of_file(source);
  const uint64_t stored = size > offset ? size - offset : 0;
  const uint64_t byte_skip = layout.byte_skip > 0 ? uint64_t(layout.byte_skip) : 0;
  if (!gzip) {
    // byte skip -1: the data are the file's last bytes.
    const uint64_t available =
        layout.byte_skip < 0 ? stored : (stored > byte_skip ? stored - byte_skip : 0);
    check_data_fits(path, needed, available, false);
    return DataPlace{source, layout.byte_skip < 0 ? size - needed : offset + byte_skip, false, 0};
  }
  // The exact count comes from inflating, once, while decoding (read_voxel_data.hpp).
  check_data_fits(path, needed + byte_skip, stored, true);
  return DataPlace{source, offset, true, byte_skip};
}

std::optional<std::string> dictionary_value(const itk::MetaDataDictionary& dictionary,
                                            const std::string& key) {
  std::string value;
  if (!dictionary.HasKey(key) || !itk::ExposeMetaData<std::string>(dictionary, key, value)) {
    return std::nullopt;
  }
  return std::string(trim(value));
}

struct Segments {
  std::vector<LabelInfo> labels;
  std::set<int> layers;
};

Segments read_segments(const fs::path& path, const itk::MetaDataDictionary& dictionary,
                       const ReadOptions& options) {
  Segments segments;
  for (int i = 0;; ++i) {
    const std::string prefix = "Segment" + std::to_string(i) + "_";
    const auto name = dictionary_value(dictionary, prefix + "Name");
    const auto id = dictionary_value(dictionary, prefix + "ID");
    const auto label_value = dictionary_value(dictionary, prefix + "LabelValue");
    if (!name && !id && !label_value) break;

    LabelInfo info;
    info.name = name ? *name : (id ? *id : "");
    info.label = i + 1;  // files older than Slicer 4.11 have one binary layer per segment
    if (label_value) {
      const char* end = label_value->data() + label_value->size();
      if (auto [ptr, ec] = std::from_chars(label_value->data(), end, info.label);
          ec != std::errc() || ptr != end) {
        throw file_error(path, prefix + "LabelValue \"" + *label_value +
                                   "\" is not an integer; the segmentation header is corrupt");
      }
    }
    if (const auto layer = dictionary_value(dictionary, prefix + "Layer")) {
      int value = 0;
      std::from_chars(layer->data(), layer->data() + layer->size(), value);
      segments.layers.insert(value);
    }
    if (const auto color = dictionary_value(dictionary, prefix + "Color")) {
      std::istringstream text(*color);
      Rgb rgb;
      if (text >> rgb.r >> rgb.g >> rgb.b && rgb.r >= 0 && rgb.r <= 1 && rgb.g >= 0 && rgb.g <= 1 &&
          rgb.b >= 0 && rgb.b <= 1) {
        info.color = rgb;
      } else {
        warn(options, path,
             prefix + "Color \"" + *color + "\" is not three numbers from 0 to 1; ignored");
      }
    }
    segments.labels.push_back(std::move(info));
  }
  return segments;
}

Error layers_error(const fs::path& path, size_t layers) {
  return file_error(path, "the segments overlap and are stored in " + std::to_string(layers) +
                              " layers, which is not supported; in 3D Slicer export the "
                              "segmentation as a label map (Segmentations module, Export to "
                              "files, or Export to labelmap volume) and read that");
}

}  // namespace

Image read_nrrd(const fs::path& path, const ReadOptions& options) {
  const NrrdLayout layout = scan_layout(path);
  // ITK opens a detached data file while reading the header: a named pipe there would block
  // forever, a device never end. One detached file is checked first (LIST and %-patterns name
  // several; ITK checks those).
  if (!layout.data_file.empty() && !names_several_files(layout.data_file)) {
    detached_data_file(path, layout.data_file, options.allow_external_data);
  }
  if (names_several_files(layout.data_file) && !options.allow_external_data) {
    throw external_data_error(path, "its data are a list or pattern of files (data file: " +
                                        layout.data_file + "), which are not checked one by one");
  }
  auto io = itk::NrrdImageIO::New();
  const ItkHeader header = read_itk_header(*io, path);
  const Segments segments = read_segments(path, io->GetMetaDataDictionary(), options);

  if (header.components > 1 || segments.layers.size() > 1) {
    if (!segments.labels.empty()) {
      throw layers_error(path, std::max<size_t>(header.components, segments.layers.size()));
    }
    throw file_error(path, "images with " + std::to_string(header.components) +
                               " values per voxel (vector or multi-layer) are not supported; "
                               "extract one component first");
  }
  if (!header.type) {
    throw file_error(path,
                     "the voxel type is not supported; save the volume with an integer or "
                     "float type");
  }
  const std::array<int64_t, 3> dims = check_dims(path, header.dims);
  check_voxel_limit(path, dims, options.max_voxels);
  check_grid(path, header.grid, "space directions / spacings");
  const uint64_t count = header.grid.voxel_count();
  const uint64_t needed = count * header.component_size;
  const std::optional<DataPlace> place =
      check_nrrd_data(path, layout, needed, options.allow_external_data);

  VoxelSink sink(path, count, *header.type);
  // Raw and gzip data we decode ourselves, in one pass (with libdeflate for gzip); ITK reads
  // the rest (and multi-byte data whose byte order the header leaves open, which it refuses).
  const bool big = layout.endian == "big";
  const size_t size = voxel_type_size(*header.type);
  if (place && size == header.component_size &&
      (size == 1 || big || layout.endian == "little")) {
    const bool swap = big != (std::endian::native == std::endian::big);
    sink.defer_value_errors();  // stream faults first, as when the data were counted first
    read_voxel_data(path, place->source, place->offset, place->compressed, place->skip, count,
                    *header.type, size > 1 && swap, sink);
  } else {
    if (place && place->compressed) {
      DataStream stream(place->source, place->offset, true);
      check_compressed_data(path, stream, place->skip, needed);
    }
    read_itk_voxels(*io, path, header, sink);
  }
  return Image{path.string(), std::string(voxel_type_name(*header.type)),
               std::move(sink).finish(header.grid), segments.labels};
}

}  // namespace segmesh::volume_io
