#include "segmesh_io/dicom_seg_reader.hpp"

#include <gdcmDataSet.h>
#include <gdcmFileMetaInformation.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfItems.h>
#include <gdcmTransferSyntax.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "segmesh_io/detail/dicom_file_check.hpp"
#include "segmesh_io/detail/dicom_geometry.hpp"
#include "segmesh_io/detail/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSegmentationStorage = "1.2.840.10008.5.1.4.1.1.66.4";

// The value of an element as text, without the padding DICOM adds (spaces, NUL); nullopt when
// the element is absent or has no value.
std::optional<std::string> text(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  const gdcm::Tag tag(group, element);
  if (!ds.FindDataElement(tag)) return std::nullopt;
  const gdcm::ByteValue* value = ds.GetDataElement(tag).GetByteValue();
  if (!value || value->GetLength() == 0) return std::nullopt;
  std::string s(value->GetPointer(), value->GetLength());
  const auto first = s.find_first_not_of(std::string(" \0", 2));
  if (first == std::string::npos) return std::nullopt;
  const auto last = s.find_last_not_of(std::string(" \0", 2));
  return s.substr(first, last - first + 1);
}

// An unsigned short (US) element's values, little endian (the only byte order read here).
std::vector<uint16_t> shorts(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  const gdcm::Tag tag(group, element);
  if (!ds.FindDataElement(tag)) return {};
  const gdcm::ByteValue* value = ds.GetDataElement(tag).GetByteValue();
  if (!value) return {};
  std::vector<uint16_t> out(value->GetLength() / 2);
  const auto* bytes = reinterpret_cast<const unsigned char*>(value->GetPointer());
  for (size_t i = 0; i < out.size(); ++i) out[i] = uint16_t(bytes[2 * i] | bytes[2 * i + 1] << 8);
  return out;
}

std::optional<uint16_t> one_short(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  const std::vector<uint16_t> v = shorts(ds, group, element);
  if (v.empty()) return std::nullopt;
  return v.front();
}

// The items of a sequence (empty when absent).
std::vector<const gdcm::DataSet*> items(const gdcm::DataSet& ds, uint16_t group, uint16_t element) {
  const gdcm::Tag tag(group, element);
  std::vector<const gdcm::DataSet*> out;
  if (!ds.FindDataElement(tag)) return out;
  const gdcm::SmartPointer<gdcm::SequenceOfItems> sq = ds.GetDataElement(tag).GetValueAsSQ();
  if (!sq) return out;
  for (gdcm::SequenceOfItems::SizeType i = 1; i <= sq->GetNumberOfItems(); ++i)  // 1-based
    out.push_back(&sq->GetItem(i).GetNestedDataSet());
  return out;
}

// The first item of functional group `group_sq` (e.g. Plane Position Sequence) in a frame's
// per-frame item, else in the shared item.
const gdcm::DataSet* functional_group(const gdcm::DataSet* per_frame, const gdcm::DataSet* shared,
                                      uint16_t group, uint16_t element) {
  for (const gdcm::DataSet* ds : {per_frame, shared}) {
    if (!ds) continue;
    const auto found = items(*ds, group, element);
    if (!found.empty()) return found.front();
  }
  return nullptr;
}

// CIELab as DICOM stores it (PS3.3 C.10.7.1.1: L 0..100, a and b -128..127 scaled to
// 0..65535, D65 white) to sRGB in 0..1.
Rgb lab_to_srgb(const std::vector<uint16_t>& lab) {
  const double l = lab[0] * 100.0 / 65535.0;
  const double a = lab[1] * 255.0 / 65535.0 - 128.0;
  const double b = lab[2] * 255.0 / 65535.0 - 128.0;
  const double fy = (l + 16) / 116, fx = fy + a / 500, fz = fy - b / 200;
  auto inverse = [](double f) {
    return f > 6.0 / 29 ? f * f * f : 3 * (6.0 / 29) * (6.0 / 29) * (f - 4.0 / 29);
  };
  const double x = 0.95047 * inverse(fx), y = inverse(fy), z = 1.08883 * inverse(fz);
  const double linear[3] = {3.2406 * x - 1.5372 * y - 0.4986 * z,
                            -0.9689 * x + 1.8758 * y + 0.0415 * z,
                            0.0557 * x - 0.2040 * y + 1.0570 * z};
  float out[3];
  for (int c = 0; c < 3; ++c) {
    const double v = std::clamp(linear[c], 0.0, 1.0);
    out[c] = float(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055);
  }
  return {out[0], out[1], out[2]};
}

struct Frame {
  uint16_t segment = 0;
  std::array<double, 3> position{};
  int64_t slice = 0;
};

}  // namespace

Image read_dicom_seg(const fs::path& file, const ReadOptions& options) {
  const DicomFileCheck check = check_dicom_file(file);
  switch (check.status) {
    case DicomFileStatus::broken:
      throw file_error(file, "broken DICOM file: " + check.reason);
    case DicomFileStatus::unreadable:
      throw file_error(file, "cannot be read (" + check.reason + ")");
    case DicomFileStatus::not_dicom:
      throw file_error(file, "is not a DICOM file (" + check.reason + ")");
    case DicomFileStatus::not_image:
      throw file_error(file, "is a DICOM file without an image");
    case DicomFileStatus::image:
      break;
  }
  silence_gdcm();
  gdcm::Reader reader;
  reader.SetFileName(file.string().c_str());
  if (!reader.Read()) throw file_error(file, "GDCM cannot read this DICOM file");
  const gdcm::DataSet& ds = reader.GetFile().GetDataSet();
  if (text(ds, 0x0008, 0x0016) != kSegmentationStorage) {
    throw file_error(file,
                     "is a single DICOM file; give the folder that holds the whole series "
                     "(a single file is read only as a DICOM SEG object)");
  }
  const gdcm::TransferSyntax& syntax = reader.GetFile().GetHeader().GetDataSetTransferSyntax();
  if (syntax.IsEncapsulated()) {
    throw file_error(file, std::string("its pixel data is compressed (transfer syntax ") +
                               syntax.GetString() +
                               "), which is not supported; decompress it first (gdcmconv --raw, "
                               "or dcmdjpeg / dcmdrle)");
  }
  if (syntax.GetSwapCode() == gdcm::SwapCode::BigEndian) {
    throw file_error(file,
                     "big-endian DICOM is not supported; convert it to little endian "
                     "(gdcmconv --raw)");
  }

  // The image pixel module.
  const auto rows = one_short(ds, 0x0028, 0x0010), columns = one_short(ds, 0x0028, 0x0011);
  const auto bits = one_short(ds, 0x0028, 0x0100);
  const auto samples = one_short(ds, 0x0028, 0x0002);
  const auto frame_text = text(ds, 0x0028, 0x0008);
  if (!rows || !columns || !bits || *rows == 0 || *columns == 0) {
    throw file_error(
        file, "Rows, Columns or Bits Allocated is missing or zero; the DICOM SEG is corrupt");
  }
  if (samples && *samples != 1)
    throw file_error(
        file, "a DICOM SEG has one sample per pixel; this one has " + std::to_string(*samples));
  const std::string type = text(ds, 0x0062, 0x0001).value_or("BINARY");
  const bool fractional = type == "FRACTIONAL";
  if (type != "BINARY" && !fractional) {
    throw file_error(file, "Segmentation Type \"" + type + "\" is neither BINARY nor FRACTIONAL");
  }
  if ((fractional && *bits != 8) || (!fractional && *bits != 1 && *bits != 8)) {
    throw file_error(file, "Bits Allocated " + std::to_string(*bits) + " for a " + type +
                               " segmentation is not valid (1 for BINARY, 8 for FRACTIONAL)");
  }
  char* end = nullptr;
  const long long frame_count = frame_text ? std::strtoll(frame_text->c_str(), &end, 10) : 1;
  if (frame_text && (end == frame_text->c_str() || frame_count < 1)) {
    throw file_error(file, "Number of Frames \"" + *frame_text + "\" is not a positive integer");
  }
  const double max_fraction = fractional ? double(one_short(ds, 0x0062, 0x000e).value_or(255)) : 1;

  // Segments: number, label, colour.
  std::vector<LabelInfo> labels;
  for (const gdcm::DataSet* segment : items(ds, 0x0062, 0x0002)) {
    const auto number = one_short(*segment, 0x0062, 0x0004);
    if (!number || *number == 0)
      throw file_error(file, "a segment has no Segment Number (or 0); the DICOM SEG is corrupt");
    LabelInfo info;
    info.label = *number;
    info.name = text(*segment, 0x0062, 0x0005).value_or("");
    const std::vector<uint16_t> lab = shorts(*segment, 0x0062, 0x000d);
    if (lab.size() == 3) info.color = lab_to_srgb(lab);
    labels.push_back(std::move(info));
  }
  if (labels.empty())
    throw file_error(file, "the Segment Sequence is empty; the DICOM SEG holds no segments");
  std::sort(labels.begin(), labels.end(),
            [](const LabelInfo& a, const LabelInfo& b) { return a.label < b.label; });
  for (size_t i = 1; i < labels.size(); ++i)
    if (labels[i].label == labels[i - 1].label)
      throw file_error(file, "segment number " + std::to_string(labels[i].label) +
                                 " appears twice in the Segment Sequence");

  // Frames: segment, position; orientation and pixel spacing the same for all.
  const auto shared_items = items(ds, 0x5200, 0x9229);
  const gdcm::DataSet* shared = shared_items.empty() ? nullptr : shared_items.front();
  const auto per_frame = items(ds, 0x5200, 0x9230);
  if (per_frame.size() != size_t(frame_count)) {
    throw file_error(file, "Number of Frames is " + std::to_string(frame_count) +
                               " but the Per-frame Functional Groups Sequence has " +
                               std::to_string(per_frame.size()) +
                               " items; the DICOM SEG is corrupt");
  }
  std::optional<std::array<double, 6>> orientation;
  std::optional<std::array<double, 2>> pixel_spacing;
  std::optional<double> slice_spacing, thickness;
  std::vector<Frame> frames(per_frame.size());
  for (size_t f = 0; f < per_frame.size(); ++f) {
    const std::string which = "frame " + std::to_string(f + 1);
    const gdcm::DataSet* id = functional_group(per_frame[f], shared, 0x0062, 0x000a);
    const auto segment = id ? one_short(*id, 0x0062, 0x000b) : std::nullopt;
    if (!segment || !find_label_info(labels, int32_t(*segment))) {
      throw file_error(
          file, which + " names no segment of the Segment Sequence; the DICOM SEG is corrupt");
    }
    frames[f].segment = *segment;
    const gdcm::DataSet* plane = functional_group(per_frame[f], shared, 0x0020, 0x9113);
    const auto position = plane ? dicom_numbers<3>(text(*plane, 0x0020, 0x0032)) : std::nullopt;
    const gdcm::DataSet* turn = functional_group(per_frame[f], shared, 0x0020, 0x9116);
    const auto o = turn ? dicom_numbers<6>(text(*turn, 0x0020, 0x0037)) : std::nullopt;
    const gdcm::DataSet* measures = functional_group(per_frame[f], shared, 0x0028, 0x9110);
    const auto spacing =
        measures ? dicom_numbers<2>(text(*measures, 0x0028, 0x0030)) : std::nullopt;
    if (!position || !o || !spacing) {
      throw file_error(file, which + " has no " +
                                 std::string(!position ? "Image Position (Patient)"
                                             : !o      ? "Image Orientation (Patient)"
                                                       : "Pixel Spacing") +
                                 "; segmesh needs each frame's place in space");
    }
    if (!orientation) {
      orientation = o;
      pixel_spacing = spacing;
      if (const auto between = dicom_numbers<1>(text(*measures, 0x0018, 0x0088)))
        slice_spacing = (*between)[0];
      if (const auto t = dicom_numbers<1>(text(*measures, 0x0018, 0x0050))) thickness = (*t)[0];
    } else {
      for (int k = 0; k < 6; ++k)
        if (std::abs((*o)[k] - (*orientation)[k]) > 1e-4)
          throw file_error(
              file,
              which +
                  " has another orientation than frame 1; frames of one DICOM SEG must share one");
      for (int k = 0; k < 2; ++k)
        if (std::abs((*spacing)[k] - (*pixel_spacing)[k]) > 1e-4 * (*pixel_spacing)[k])
          throw file_error(file, which + " has another pixel spacing than frame 1");
    }
    frames[f].position = *position;
  }

  // The grid: along the normal from the lowest frame; in the plane every frame must start at the
  // same place.
  const Vec3d normal = normal_of(*orientation);
  auto along = [&](const Frame& fr) {
    return dot(Vec3d{fr.position[0], fr.position[1], fr.position[2]}, normal);
  };
  const Frame& lowest =
      *std::min_element(frames.begin(), frames.end(),
                        [&](const Frame& a, const Frame& b) { return along(a) < along(b); });
  const double low = along(lowest);
  std::vector<double> levels;
  for (const Frame& fr : frames) levels.push_back(along(fr) - low);
  std::sort(levels.begin(), levels.end());
  double gap = 0;
  for (size_t i = 1; i < levels.size(); ++i)
    if (levels[i] - levels[i - 1] > 1e-4 && (gap == 0 || levels[i] - levels[i - 1] < gap))
      gap = levels[i] - levels[i - 1];
  double spacing_z = slice_spacing && *slice_spacing > 0 ? *slice_spacing : gap;
  if (!(spacing_z > 0)) {  // one slice: its thickness, else the pixel spacing
    spacing_z = thickness && *thickness > 0 ? *thickness : (*pixel_spacing)[0];
  }
  int64_t slices = 1;
  const Vec3d origin{lowest.position[0], lowest.position[1], lowest.position[2]};
  for (Frame& fr : frames) {
    const Vec3d p{fr.position[0], fr.position[1], fr.position[2]};
    const double k = (dot(p, normal) - low) / spacing_z;
    fr.slice = std::llround(k);
    const Vec3d sideways = (p - origin) - dot(p - origin, normal) * normal;
    const bool beside = norm(sideways) > 0.01 * std::min((*pixel_spacing)[0], (*pixel_spacing)[1]);
    if (beside || std::abs(k - double(fr.slice)) > 0.01) {
      throw file_error(file, std::string("its frames do not lie on one grid (a frame ") +
                                 (beside ? "beside the others" : "between slices") +
                                 "); segmesh reads DICOM SEG objects whose frames are slices of "
                                 "one volume");
    }
    slices = std::max(slices, fr.slice + 1);
  }
  Grid grid;
  grid.dims = {int64_t(*columns), int64_t(*rows), slices};
  grid.spacing = {(*pixel_spacing)[1], (*pixel_spacing)[0], spacing_z};
  grid.origin = {origin.x, origin.y, origin.z};
  set_slice_directions(grid, *orientation);
  check_voxel_limit(file, grid.dims, options.max_voxels);
  check_grid(file, grid, "Pixel Spacing and the frame positions");

  // Pixels.
  const gdcm::Tag pixel_tag(0x7fe0, 0x0010);
  const gdcm::ByteValue* pixels =
      ds.FindDataElement(pixel_tag) ? ds.GetDataElement(pixel_tag).GetByteValue() : nullptr;
  if (!pixels) throw file_error(file, "has no pixel data");
  const uint64_t per_frame_pixels = uint64_t(*rows) * *columns;
  const uint64_t needed =
      *bits == 1 ? (per_frame_pixels * frames.size() + 7) / 8 : per_frame_pixels * frames.size();
  if (pixels->GetLength() < needed) throw truncated_error(file, needed, pixels->GetLength());
  const auto* data = reinterpret_cast<const unsigned char*>(pixels->GetPointer());

  Image image;
  image.path = file.string();
  image.voxel_type = *bits == 1 ? "bit" : "uint8";
  std::map<std::pair<int, int>, uint64_t> overlaps;
  // The label map in the narrowest type that holds every segment number.
  auto fill = [&](auto zero) {
    using T = decltype(zero);
    std::vector<T> voxels(grid.voxel_count(), T{0});
    for (size_t f = 0; f < frames.size(); ++f) {
      const T segment = T(frames[f].segment);
      T* slice = voxels.data() + uint64_t(frames[f].slice) * per_frame_pixels;
      const uint64_t first = f * per_frame_pixels;
      for (uint64_t i = 0; i < per_frame_pixels; ++i) {
        const uint64_t n = first + i;
        const bool inside = *bits == 1   ? (data[n >> 3] >> (n & 7)) & 1
                            : fractional ? data[n] > max_fraction / 2
                                         : data[n] != 0;
        if (!inside) continue;
        T& v = slice[i];
        if (v != 0 && v != segment)
          ++overlaps[{std::min<int>(v, segment), std::max<int>(v, segment)}];
        v = std::max(v, segment);
      }
    }
    image.volume = Volume<T>{grid, std::move(voxels)};
  };
  if (labels.back().label > 255) {
    fill(uint16_t{0});
  } else {
    fill(uint8_t{0});
  }
  if (!overlaps.empty()) {
    std::string list;
    uint64_t total = 0;
    for (const auto& [pair, count] : overlaps) {
      if (list.size() < 200)
        list += (list.empty() ? "" : ", ") + std::to_string(pair.first) + " and " +
                std::to_string(pair.second);
      total += count;
    }
    warn(options, file,
         "segments overlap (" + list + ") in " + std::to_string(total) +
             " voxels; a label map holds one label per voxel, so each keeps the higher segment "
             "number");
  }
  image.labels = std::move(labels);
  return image;
}

}  // namespace segmesh::volume_io
