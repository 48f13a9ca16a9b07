#include "segmesh_io/cohort_inputs.hpp"

#include <glob.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>
#include <set>
#include <system_error>

#include "segmesh/error.hpp"
#include "segmesh_io/case_runner.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/label_names.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh {

namespace fs = std::filesystem;

namespace {

bool is_manifest(const fs::path& path) {
  const std::string ext = lower(path.extension().string());
  return ext == ".csv" || ext == ".tsv";
}

// The fields of one manifest line: tab-separated, or comma-separated with RFC 4180 quotes
// ("1,2" for a list of labels). Returns false for an unterminated quote.
bool split_fields(std::string_view line, char separator, std::vector<std::string>& fields) {
  fields.assign(1, {});
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c != '"') {
        fields.back() += c;
      } else if (i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else {
        quoted = false;
      }
    } else if (c == '"' && separator == ',') {
      quoted = true;
    } else if (c == separator) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  for (std::string& f : fields) f = std::string(trim(f));
  return !quoted;
}

// A column's option name: "min_voxels" -> "min-voxels"; empty for "path" and "case".
std::string column_option(const fs::path& manifest, const std::string& column) {
  std::string name = lower(column);
  std::replace(name.begin(), name.end(), '_', '-');
  if (name == "path" || name == "case" || name == "label-names") return name;
  if (!find_meshing_option(name)) {
    throw Error(manifest.string() + ": unknown column \"" + column +
                "\"; expected path, case, label_names or an option of segmesh mesh (smooth, "
                "iterations, labels, ...)");
  }
  return name;
}

void read_manifest(const fs::path& manifest, std::vector<CohortCase>& cases) {
  std::ifstream in(manifest);
  if (!in) throw Error(manifest.string() + ": cannot open the manifest");
  const char separator = lower(manifest.extension().string()) == ".tsv" ? '\t' : ',';
  std::vector<std::string> columns, fields;
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const std::string where = manifest.string() + ":" + std::to_string(line_number);
    if (trim(line).empty() || trim(line).front() == '#') continue;
    if (!split_fields(line, separator, fields)) throw Error(where + ": a quote is not closed");
    if (columns.empty()) {
      for (const std::string& f : fields) columns.push_back(column_option(manifest, f));
      if (std::find(columns.begin(), columns.end(), "path") == columns.end()) {
        throw Error(manifest.string() + ": the first row must name the columns, one of them path");
      }
      continue;
    }
    if (fields.size() > columns.size()) {
      throw Error(where + ": " + std::to_string(fields.size()) + " fields but " +
                  std::to_string(columns.size()) + " columns");
    }
    CohortCase c{.origin = where, .manifest_folder = manifest.parent_path()};
    for (size_t i = 0; i < fields.size(); ++i) {
      if (fields[i].empty()) continue;
      if (columns[i] == "path") {
        const fs::path p = fields[i];
        c.input = p.is_absolute() ? p : manifest.parent_path() / p;
      } else if (columns[i] == "case") {
        c.name = fields[i];
      } else {
        c.options.emplace_back(columns[i], fields[i]);
      }
    }
    if (c.input.empty()) throw Error(where + ": the path is empty");
    cases.push_back(std::move(c));
  }
  if (columns.empty()) throw Error(manifest.string() + ": the manifest is empty");
}

// Whether `file` starts like a DICOM file: "DICM" after the 128-byte preamble (Part 10).
bool looks_like_dicom(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[132] = {};
  return in.read(magic, sizeof magic) && std::string_view(magic + 128, 4) == "DICM";
}

bool hidden(const fs::path& path) { return path.filename().string().starts_with("."); }

// A folder's cases (see the header): the whole tree below it, hidden entries and `exclude` (the
// output folder, which may lie inside) left out.
void expand_folder(const fs::path& folder, const fs::path& exclude, std::vector<CohortCase>& cases) {
  std::vector<fs::path> found;
  std::error_code ec;
  const fs::path skip = exclude.empty() ? fs::path{} : fs::weakly_canonical(exclude, ec);
  // Folders to look in, depth first; a folder holding no volume file, no sub-folder and a file
  // that starts like DICOM is a series.
  std::vector<fs::path> stack{folder};
  while (!stack.empty()) {
    const fs::path here = stack.back();
    stack.pop_back();
    std::vector<fs::path> files;
    bool subfolders = false, volume_files = false;
    for (const fs::directory_entry& e : fs::directory_iterator(here, ec)) {
      if (hidden(e.path())) continue;
      if (e.is_directory()) {
        if (!skip.empty() && fs::weakly_canonical(e.path(), ec) == skip) continue;
        subfolders = true;
        stack.push_back(e.path());
      } else if (e.is_regular_file()) {
        files.push_back(e.path());
        if (!volume_extension(e.path()).empty()) {
          volume_files = true;
          found.push_back(e.path());
        }
      }
    }
    if (!volume_files && !subfolders && !files.empty()) {
      std::sort(files.begin(), files.end());
      // The top folder itself is a series as `segmesh mesh` reads it, whatever its files.
      if (here == folder || looks_like_dicom(files.front())) found.push_back(here);
    }
  }
  if (found.empty()) {
    throw Error(folder.string() + ": holds no volume file and no DICOM series, in it or below");
  }
  std::sort(found.begin(), found.end());
  for (const fs::path& p : found) cases.push_back({.input = p});
}

// Case names: the file names without their volume extension; where several cases would share
// one, the names of the folders above are put in front, one more at a time, until they differ
// (s0001/ct.nii.gz and s0002/ct.nii.gz are s0001_ct and s0002_ct); what still collides gets
// _2, _3, ... (unique_stem). A manifest's `case` column is taken as given.
void name_cases(std::vector<CohortCase>& cases) {
  const size_t n = cases.size();
  std::vector<int> depth(n, 0);
  auto name_at = [&](size_t i) {
    const CohortCase& c = cases[i];
    if (!c.name.empty()) return file_stem_for(c.name, "case");
    std::string name = case_name(c.input);
    fs::path up = c.input.lexically_normal();
    if (up.filename().empty()) up = up.parent_path();  // "dicom/"
    up = up.parent_path();
    for (int d = 0; d < depth[i] && !up.filename().empty(); ++d, up = up.parent_path()) {
      const std::string folder = up.filename().string();
      if (folder == "." || folder == "..") break;
      name = folder + "_" + name;
    }
    return file_stem_for(name, "case");
  };
  // Each group of cases sharing a name goes as many folders up as it takes for its names to
  // differ more (a/x/seg and b/x/seg: two), and not at all when they never do (one file twice).
  constexpr int kMaxDepth = 4;
  for (bool changed = true; changed;) {
    changed = false;
    std::map<std::string, std::vector<size_t>> by_name;
    for (size_t i = 0; i < n; ++i) by_name[lower(name_at(i))].push_back(i);
    for (const auto& [name, group] : by_name) {
      if (group.size() < 2 || !cases[group[0]].name.empty()) continue;
      const int from = depth[group[0]];
      for (int d = from + 1; d <= kMaxDepth; ++d) {
        std::set<std::string> distinct;
        for (size_t i : group) {
          depth[i] = d;
          distinct.insert(lower(name_at(i)));
        }
        if (distinct.size() > 1) {
          changed = true;
          break;
        }
        if (d == kMaxDepth)
          for (size_t i : group) depth[i] = from;
      }
    }
  }
  UniqueNames used(/*fold_case=*/true);
  for (size_t i = 0; i < n; ++i) cases[i].name = unique_stem(name_at(i), used);
}

void expand_glob(const std::string& pattern, std::vector<CohortCase>& cases) {
  glob_t matches{};
  const int rc = ::glob(pattern.c_str(), 0, nullptr, &matches);
  std::vector<fs::path> paths(matches.gl_pathv, matches.gl_pathv + matches.gl_pathc);
  ::globfree(&matches);
  if (rc != 0 || paths.empty()) throw Error(pattern + ": matches no file");
  std::sort(paths.begin(), paths.end());
  for (const fs::path& p : paths) cases.push_back({.input = p});
}

}  // namespace

std::vector<CohortCase> expand_cohort_inputs(const std::vector<std::string>& inputs,
                                             const std::filesystem::path& exclude) {
  std::vector<CohortCase> cases;
  for (const std::string& input : inputs) {
    std::error_code ec;
    const fs::file_status status = fs::status(input, ec);
    if (fs::is_directory(status)) {
      expand_folder(input, exclude, cases);
    } else if (fs::is_regular_file(status) && is_manifest(input)) {
      read_manifest(input, cases);
    } else if (!fs::exists(status) && input.find_first_of("*?[") != std::string::npos) {
      expand_glob(input, cases);
    } else {
      cases.push_back({.input = input});
    }
  }
  name_cases(cases);
  return cases;
}

MeshingOptions case_options(const MeshingOptions& defaults, const CohortCase& c,
                            std::string& label_names_file) {
  MeshingOptions options = defaults;
  try {
    for (const auto& [name, text] : c.options) {
      if (name == "label-names") {
        const fs::path p = text;
        label_names_file = (p.is_absolute() ? p : c.manifest_folder / p).string();
        options.label_names = read_label_names(label_names_file);
      } else {
        find_meshing_option(name)->set(options, text);
      }
    }
    resolve_meshing_options(options);
  } catch (const Error& e) {
    throw Error(c.origin.empty() ? std::string(e.what()) : c.origin + ": " + e.what());
  }
  return options;
}

MeshFormat cohort_format(const std::string& name) {
  const std::optional<MeshFormat> format = parse_mesh_format(name);
  if (!format) throw Error("--format must be stl, ply, obj or glb (got \"" + name + "\")");
  return *format;
}

void check_cohort_settings(const CohortSettings& s) {
  if (s.write.quantize && s.format != MeshFormat::glb) {
    throw Error("--quantize writes glTF's KHR_mesh_quantization; it needs --format glb");
  }
  if (s.color != "material" && s.color != "quality") {
    throw Error("--color must be material or quality (got \"" + s.color + "\")");
  }
  if (s.threads < 0) throw Error("--threads must be 0 (all cores) or more");
  if (s.read.max_voxels == 0) throw Error("--max-voxels must be at least 1");
}

fs::path cohort_output_folder(const fs::path& output) {
  fs::path out = output.lexically_normal();
  if (!out.has_filename()) out = out.parent_path();  // "out/" -> "out"
  return out;
}

CaseRequest case_request(const CohortCase& c, const fs::path& out_dir, const CohortSettings& s) {
  CaseRequest q{.input = c.input,
                .name = c.name,
                .out_dir = out_dir,
                .label_names = s.label_names_file,
                .format = s.format,
                .per_part = s.per_part,
                .write = s.write,
                .color = s.color,
                .threads = s.threads,
                .read = s.read,
                .force = s.force};
  q.options = case_options(s.defaults, c, q.label_names);
  return q;
}

Shard parse_shard(std::string_view text) {
  Shard s;
  const size_t slash = text.find('/');
  if (slash == std::string_view::npos || !parse_number(text.substr(0, slash), s.index) ||
      !parse_number(text.substr(slash + 1), s.count) || s.count < 1 || s.index < 1 ||
      s.index > s.count) {
    throw Error("--shard must be I/N with 1 <= I <= N, e.g. 2/8 (got \"" + std::string(text) +
                "\")");
  }
  return s;
}

}  // namespace segmesh
