#include "segmesh_io/case_runner.hpp"

#include <unistd.h>

#include <chrono>
#include <fstream>
#include <new>
#include <nlohmann/json.hpp>
#include <system_error>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/mesh_job.hpp"

namespace segmesh {

namespace fs = std::filesystem;

namespace {

constexpr const char* kMarker = "case.json";

// The hidden siblings of OUT/name: ".name.tmp-<pid>" (being written), ".name.old-<pid>" (the
// folder a forced run replaces).
std::string sibling_prefix(const std::string& name, const char* kind) {
  return "." + name + "." + kind + "-";
}

// ".name.tmp-<digits>" or ".name.old-<digits>": only this case's own siblings. The digits matter:
// case "a"'s prefix ".a.tmp-" also begins the temporary folder of a case named "a.tmp-1"
// (".a.tmp-1.tmp-<pid>"), which may be running beside it.
bool is_case_sibling(const std::string& file, const std::string& prefix) {
  if (!file.starts_with(prefix) || file.size() == prefix.size()) return false;
  return file.find_first_not_of("0123456789", prefix.size()) == std::string::npos;
}

nlohmann::json marker_json(const CaseResult& r) {
  return {{"case", r.name},       {"input", r.input},         {"status", "ok"},
          {"parts", r.parts},     {"triangles", r.triangles}, {"volume_mm3", r.volume_mm3},
          {"seconds", r.seconds}};
}

// The one line a failed case records.
std::string failure_message(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    return e.what();
  } catch (const fs::filesystem_error& e) {
    const std::string where = e.path1().empty() ? "segmesh" : e.path1().string();
    return where + ": " + e.code().message();
  } catch (const std::bad_alloc&) {
    return "out of memory; try a smaller volume or fewer labels";
  } catch (const std::exception& e) {
    return std::string("internal error: ") + e.what();
  }
}

// Meshes the case into `folder` (the temporary one) and fills in the row's numbers.
void mesh_case(const CaseRequest& q, const fs::path& folder, CaseResult& row, Progress& progress,
               std::chrono::steady_clock::time_point start) {
  const MeshingOptions request = q.options;
  MeshingOptions options = resolve_meshing_options(request);
  if (q.color != "material" && q.color != "quality") {
    throw Error("--color must be material or quality (got \"" + q.color + "\")");
  }
  options.color_by_quality = q.color == "quality";
  const std::string file = "scene." + std::string(extension(q.format));
  const fs::path final_folder = q.out_dir / q.name;
  MeshTarget reported{.path = q.per_part ? final_folder : final_folder / file,
                      .folder = q.per_part,
                      .format = q.format};
  MeshTarget write_to = reported;
  write_to.path = q.per_part ? folder : folder / file;
  if (q.write.quantize && q.format != MeshFormat::glb) {
    throw Error("--quantize writes glTF's KHR_mesh_quantization; it needs glb output, not " +
                std::string(extension(q.format)));
  }

  MeshTimings t;
  progress.step("reading");
  Image image = read_volume(q.input, q.read);
  t.read = ms_since(start);
  const MeshJob job{.request = {.options = options,
                                .label_names = q.label_names,
                                .target = reported,
                                .write = q.write,
                                .threads = q.threads,
                                .color = q.color,
                                .surfaces_note = surfaces_note(request)},
                    .report = folder / "report.json",
                    .measure = true,
                    .write_to = write_to};
  const MeshJobResult result = run_mesh_job(image, job, progress, t, start);
  row.parts = static_cast<int64_t>(result.scene.parts.size());
  for (const PartMeasures& m : result.measures.parts) {
    row.triangles += m.mesh.triangles;
    row.volume_mm3 += m.mesh.volume_mm3;
  }
}

}  // namespace

std::string_view case_status_name(CaseStatus status) {
  switch (status) {
    case CaseStatus::ok: return "ok";
    case CaseStatus::failed: return "failed";
    case CaseStatus::skipped: return "skipped";
    case CaseStatus::pending: return "pending";
  }
  return "pending";
}

void remove_case_temporaries(const fs::path& out_dir, const std::string& name) {
  const std::string tmp = sibling_prefix(name, "tmp"), old = sibling_prefix(name, "old");
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const fs::directory_entry& e : fs::directory_iterator(out_dir, ec)) {
    const std::string file = e.path().filename().string();
    if (is_case_sibling(file, tmp) || is_case_sibling(file, old)) stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove_all(p, ec);
}

std::optional<CaseResult> finished_case(const fs::path& out_dir, const std::string& name,
                                        const fs::path& input) {
  std::ifstream in(out_dir / name / kMarker);
  if (!in) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || j.value("status", "") != "ok" || j.value("input", "") != input.string()) {
    return std::nullopt;
  }
  try {
    return CaseResult{.name = name,
                      .input = input.string(),
                      .status = CaseStatus::skipped,
                      .parts = j.at("parts").get<int64_t>(),
                      .triangles = j.at("triangles").get<int64_t>(),
                      .volume_mm3 = j.at("volume_mm3").get<double>(),
                      .seconds = j.at("seconds").get<double>()};
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

CaseResult run_case(const CaseRequest& q, Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  CaseResult row{.name = q.name, .input = q.input.string()};
  remove_case_temporaries(q.out_dir, q.name);
  if (!q.force) {
    if (std::optional<CaseResult> done = finished_case(q.out_dir, q.name, q.input)) return *done;
  }
  const std::string pid = std::to_string(::getpid());
  const fs::path final_folder = q.out_dir / q.name;
  const fs::path temp = q.out_dir / (sibling_prefix(q.name, "tmp") + pid);
  const fs::path old = q.out_dir / (sibling_prefix(q.name, "old") + pid);
  std::error_code ec;
  try {
    if (!fs::create_directory(temp, ec) && ec) {
      throw Error(temp.string() + ": cannot create the case's folder (" + ec.message() + ")");
    }
    mesh_case(q, temp, row, progress, start);
    row.status = CaseStatus::ok;
    row.seconds = ms_since(start) / 1000;
    AtomicFile marker(temp / kMarker);
    marker.stream() << marker_json(row).dump(2) << '\n';
    marker.commit();
    // The old folder goes aside first: a folder cannot be renamed over a non-empty one.
    if (fs::exists(fs::symlink_status(final_folder))) fs::rename(final_folder, old);
    fs::rename(temp, final_folder);
    fs::remove_all(old, ec);
  } catch (const Cancelled&) {
    fs::remove_all(temp, ec);
    throw;
  } catch (...) {
    fs::remove_all(temp, ec);
    row = CaseResult{.name = q.name,
                     .input = q.input.string(),
                     .status = CaseStatus::failed,
                     .seconds = ms_since(start) / 1000,
                     .error = failure_message(std::current_exception())};
  }
  return row;
}

std::string case_name(const fs::path& input) {
  std::string file = input.filename().string();
  if (file.empty()) file = input.parent_path().filename().string();  // "dicom/"
  file.resize(file.size() - volume_extension(file).size());
  return file_stem_for(file, "case");
}

}  // namespace segmesh
