#include "segmesh_io/dicom_series.hpp"

#include <itkGDCMImageIO.h>
#include <itkMetaDataObject.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "segmesh_io/detail/dicom_file_check.hpp"
#include "segmesh_io/detail/dicom_geometry.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/volume_itk.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

struct Slice {
  fs::path file;
  std::string series_uid;
  int64_t columns = 0;
  int64_t rows = 0;
  std::optional<std::array<double, 6>> orientation;  // ImageOrientationPatient
  std::optional<std::array<double, 3>> position;     // ImagePositionPatient
  double along_normal = 0;
};

std::optional<std::string> tag(const itk::MetaDataDictionary& dictionary, const std::string& key) {
  std::string value;
  if (!dictionary.HasKey(key) || !itk::ExposeMetaData<std::string>(dictionary, key, value)) {
    return std::nullopt;
  }
  const auto first = value.find_first_not_of(" \0", 0, 2);
  const auto last = value.find_last_not_of(" \0", std::string::npos, 2);
  return first == std::string::npos ? std::string() : value.substr(first, last - first + 1);
}

std::string number_text(double value) {
  std::ostringstream text;
  text.precision(4);
  text << value;
  return text.str();
}

bool has_dicom_extension(const fs::path& file) {
  const std::string ext = lower(file.extension().string());
  return ext == ".dcm" || ext == ".dicom" || ext == ".ima";
}


// Pass 1: what each file is, from its header. Non-images are skipped with a warning.
std::vector<Slice> scan_folder(const fs::path& folder, const ReadOptions& options) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.is_regular_file(ec)) files.push_back(entry.path());
  }
  if (ec) throw file_error(folder, "cannot list the folder (" + ec.message() + ")");
  std::sort(files.begin(), files.end());

  std::vector<Slice> slices;
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    // Our own structural check first: GDCM aborts on some truncated files and reads others with
    // missing pixels (dicom_file_check.hpp).
    const DicomFileCheck check = check_dicom_file(file);
    switch (check.status) {
      case DicomFileStatus::broken:
        throw file_error(file, "is a broken DICOM file (" + check.reason +
                                   "); replace it with a complete copy or remove it from the folder");
      case DicomFileStatus::not_dicom:
        if (has_dicom_extension(file)) {
          throw file_error(file, "is named like a DICOM file but is not one (" + check.reason +
                                     "); replace it with a complete copy or remove it from the folder");
        }
        warn(options, folder, "skipping " + name + ": not a DICOM file");
        continue;
      case DicomFileStatus::not_image:
        warn(options, folder, "skipping " + name + ": a DICOM file without an image");
        continue;
      case DicomFileStatus::unreadable:
        // It may be a slice: skipping it could leave a gap at the end of the series that no
        // spacing check sees.
        throw file_error(file, "cannot be read (" + check.reason +
                                   "); give read permission or remove it from the folder");
      case DicomFileStatus::image:
        break;
    }
    auto io = itk::GDCMImageIO::New();
    try {
      if (!io->CanReadFile(file.string().c_str())) {
        warn(options, folder, "skipping " + name + ": not a DICOM file");
        continue;
      }
      io->SetFileName(file.string());
      io->ReadImageInformation();
    } catch (const itk::ExceptionObject&) {
      warn(options, folder, "skipping " + name + ": not a readable DICOM image");
      continue;
    }
    if (io->GetNumberOfDimensions() > 2 && io->GetDimensions(2) > 1) {
      warn(options, folder,
           "skipping " + name +
               ": a multi-frame object (a DICOM SEG is read on its own: give its file)");
      continue;
    }
    const auto& dictionary = io->GetMetaDataDictionary();
    Slice slice;
    slice.file = file;
    slice.series_uid = tag(dictionary, "0020|000e").value_or("");
    slice.columns = static_cast<int64_t>(io->GetDimensions(0));
    slice.rows = static_cast<int64_t>(io->GetDimensions(1));
    slice.orientation = dicom_numbers<6>(tag(dictionary, "0020|0037"));
    slice.position = dicom_numbers<3>(tag(dictionary, "0020|0032"));
    slices.push_back(std::move(slice));
  }
  return slices;
}

std::string group_key(const Slice& slice) {
  std::string key =
      slice.series_uid + "|" + std::to_string(slice.columns) + "x" + std::to_string(slice.rows);
  if (slice.orientation) {
    for (double v : *slice.orientation) {
      char text[32];
      std::snprintf(text, sizeof text, "|%.3f", v + 0.0);  // + 0.0: no "-0.000"
      key += text;
    }
  }
  return key;
}

std::string describe(const std::vector<Slice>& group) {
  const Slice& first = group.front();
  const std::string uid = first.series_uid.empty() ? "without a UID" : first.series_uid;
  return "series " + uid + " (" + std::to_string(first.columns) + "x" + std::to_string(first.rows) +
         ", " + std::to_string(group.size()) + (group.size() == 1 ? " slice)" : " slices)");
}

// The series with most slices; a warning names the others.
std::vector<Slice> choose_series(const fs::path& folder, std::vector<Slice> slices,
                                 const ReadOptions& options) {
  std::map<std::string, std::vector<Slice>> groups;
  for (Slice& slice : slices) groups[group_key(slice)].push_back(std::move(slice));
  auto chosen = groups.begin();
  for (auto it = groups.begin(); it != groups.end(); ++it) {
    if (it->second.size() > chosen->second.size()) chosen = it;
  }
  if (groups.size() > 1) {
    std::string others;
    for (auto it = groups.begin(); it != groups.end(); ++it) {
      if (it == chosen) continue;
      others += (others.empty() ? "" : ", ") + describe(it->second);
    }
    warn(options, folder,
         "holds " + std::to_string(groups.size()) + " series; reading " + describe(chosen->second) +
             " and ignoring " + others);
  }
  return std::move(chosen->second);
}

// Sorts along the slice normal and returns the slice spacing; refuses what cannot be a regular
// volume.
double order_slices(const fs::path& folder, std::vector<Slice>& slices,
                    const ReadOptions& options) {
  for (const Slice& slice : slices) {
    if (!slice.position || !slice.orientation) {
      throw file_error(folder, slice.file.filename().string() +
                                   " has no Image Position/Orientation (Patient), so the slices "
                                   "cannot be ordered in space; this is not a CT/MR image series");
    }
  }
  const Vec3d normal = normal_of(*slices.front().orientation);
  if (!(norm(normal) > 0.5)) {
    throw file_error(folder, "the Image Orientation (Patient) of " +
                                 slices.front().file.filename().string() + " is degenerate");
  }
  for (Slice& slice : slices) {
    const auto& p = *slice.position;
    slice.along_normal = dot({p[0], p[1], p[2]}, normal);
  }
  std::stable_sort(slices.begin(), slices.end(),
                   [](const Slice& a, const Slice& b) { return a.along_normal < b.along_normal; });
  if (slices.size() < 2) {
    throw file_error(folder, "holds only one image slice (" +
                                 slices.front().file.filename().string() +
                                 "); a volume needs at least two");
  }

  std::vector<double> gaps;
  for (size_t i = 1; i < slices.size(); ++i)
    gaps.push_back(slices[i].along_normal - slices[i - 1].along_normal);
  for (size_t i = 0; i < gaps.size(); ++i) {
    if (gaps[i] < 1e-4) {
      throw file_error(folder, slices[i].file.filename().string() + " and " +
                                   slices[i + 1].file.filename().string() +
                                   " lie at the same position (" +
                                   number_text(slices[i].along_normal) +
                                   " mm along the slice normal); the folder mixes several "
                                   "acquisitions, put each in its own folder");
    }
  }
  std::vector<double> sorted = gaps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double typical = sorted[sorted.size() / 2];
  const double tolerance = std::max(0.01 * typical, 1e-3);
  size_t irregular = 0;
  std::optional<size_t> first_irregular;
  for (size_t i = 0; i < gaps.size(); ++i) {
    if (std::abs(gaps[i] - typical) > tolerance) {
      ++irregular;
      if (!first_irregular) first_irregular = i;
    }
  }
  if (first_irregular) {
    const size_t i = *first_irregular;
    std::string more =
        irregular > 1 ? " (and " + std::to_string(irregular - 1) + " more uneven gaps)" : "";
    throw file_error(folder, "the slices are not evenly spaced: " + number_text(gaps[i]) +
                                 " mm between " + slices[i].file.filename().string() + " and " +
                                 slices[i + 1].file.filename().string() + " where the others are " +
                                 number_text(typical) + " mm apart" + more +
                                 "; a slice is probably missing");
  }

  const auto& first = *slices.front().position;
  const auto& last = *slices.back().position;
  const Vec3d span{last[0] - first[0], last[1] - first[1], last[2] - first[2]};
  const double along = dot(span, normal);
  const double sideways = norm(span - along * normal);
  if (sideways > 0.01 * std::abs(along) + 1e-3) {
    warn(options, folder,
         "the slices are sheared (gantry tilt of " +
             number_text(std::atan2(sideways, along) * 180 / std::numbers::pi) +
             " degrees); the volume is read as if they were stacked straight");
  }
  return along / double(slices.size() - 1);
}

}  // namespace

Image read_dicom_series(const fs::path& folder, const ReadOptions& options) {
  silence_gdcm();
  std::vector<Slice> slices = scan_folder(folder, options);
  if (slices.empty()) {
    throw file_error(folder,
                     "no DICOM images found in this folder; give the folder that holds "
                     "the slices of one CT or MR series");
  }
  slices = choose_series(folder, std::move(slices), options);
  const double slice_spacing = order_slices(folder, slices, options);

  Grid grid;
  grid.dims = {slices.front().columns, slices.front().rows, int64_t(slices.size())};
  check_voxel_limit(folder, grid.dims, options.max_voxels);
  set_slice_directions(grid, *slices.front().orientation);
  const auto& origin = *slices.front().position;
  grid.origin = {origin[0], origin[1], origin[2]};

  // Pass 2: pixels, slice by slice in spatial order.
  std::optional<VoxelSink> sink;
  std::string voxel_type;
  for (const Slice& slice : slices) {
    auto io = itk::GDCMImageIO::New();
    const ItkHeader header = read_itk_header(*io, slice.file);
    if (header.grid.dims[0] != grid.dims[0] || header.grid.dims[1] != grid.dims[1] ||
        header.components != 1 || !header.type) {
      throw file_error(slice.file,
                       "changed while reading, or holds colour or unsupported pixel data");
    }
    if (!sink) {
      grid.spacing = {header.grid.spacing[0], header.grid.spacing[1], slice_spacing};
      check_grid(folder, grid, "PixelSpacing and the slice positions");
      const int internal = static_cast<int>(io->GetInternalComponentType());
      const VoxelType stored = voxel_type_from_itk(internal).value_or(*header.type);
      voxel_type = std::string(voxel_type_name(stored));
      sink.emplace(folder, grid.voxel_count(), stored);
    }
    read_itk_voxels(*io, slice.file, header, *sink);
  }
  return Image{folder.string(), voxel_type, std::move(*sink).finish(grid), {}};
}

}  // namespace segmesh::volume_io
