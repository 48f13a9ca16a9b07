#include "python_cohort.hpp"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "python_options.hpp"
#include "python_progress.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/case_runner.hpp"
#include "segmesh_io/case_summary.hpp"
#include "segmesh_io/cohort_inputs.hpp"
#include "segmesh_io/label_names.hpp"

namespace segmesh::python {

namespace fs = std::filesystem;

namespace {

// The settings every case of a run shares, as the Python side passes them (a dict, so that the
// names stay in one place there), checked as `segmesh batch` checks its command line.
CohortSettings settings_from(const py::dict& s) {
  CohortSettings c{.format = cohort_format(s["format"].cast<std::string>()),
                   .per_part = s["per_part"].cast<bool>(),
                   .write = {.quantize = s["quantize"].cast<bool>()},
                   .color = s["color"].cast<std::string>(),
                   .threads = s["threads"].cast<int>(),
                   .read = {.max_voxels = s["max_voxels"].cast<uint64_t>(),
                            .allow_external_data = s["allow_external_data"].cast<bool>()},
                   .force = s["force"].cast<bool>()};
  check_cohort_settings(c);
  c.defaults = options_from_kwargs(s["options"].cast<py::dict>());
  const py::object names = s["label_names"];
  c.defaults.label_names = label_names_from(names);  // checks it
  if (!names.is_none() && !py::isinstance<py::dict>(names)) {
    c.label_names_file = names.cast<fs::path>().string();  // a TSV file: the report names it
  }
  resolve_meshing_options(c.defaults);
  return c;
}

py::dict case_dict(const CohortCase& c, size_t index) {
  py::dict d;
  d["input"] = c.input.string();
  d["name"] = c.name;
  py::list options;
  for (const auto& [name, text] : c.options) options.append(py::make_tuple(name, text));
  d["options"] = options;
  d["origin"] = c.origin;
  d["manifest_folder"] = c.manifest_folder.string();
  d["index"] = index;
  return d;
}

CohortCase case_from(const py::object& input, const py::object& name) {
  CohortCase c;
  if (py::isinstance<py::dict>(input)) {
    const py::dict d = input.cast<py::dict>();
    c.input = d["input"].cast<fs::path>();
    c.name = d["name"].cast<std::string>();
    for (const auto& item : d["options"]) {
      c.options.push_back(item.cast<std::pair<std::string, std::string>>());
    }
    c.origin = d["origin"].cast<std::string>();
    c.manifest_folder = d["manifest_folder"].cast<fs::path>();
  } else {
    c.input = input.cast<fs::path>();
    c.name = case_name(c.input);
  }
  if (!name.is_none()) c.name = name.cast<std::string>();
  if (c.name.empty() || c.name != case_name(c.name + ".nrrd")) {
    throw Error("case name \"" + c.name + "\" is not a folder name (letters, digits, '-', '_', "
                "'.'; not starting with a dot)");
  }
  return c;
}

// The cases of `inputs` this run takes (the shard's), every one's options checked; nothing is
// written. {"cases": [case dicts], "total": cases in the whole cohort, "out_dir": OUT}.
py::dict cohort(const std::vector<std::string>& inputs, const fs::path& out_dir,
                const std::string& shard_text, const py::dict& settings) {
  const Shard shard = shard_text.empty() ? Shard{} : parse_shard(shard_text);
  const CohortSettings s = settings_from(settings);
  const fs::path out = cohort_output_folder(out_dir);
  std::vector<CohortCase> cases;
  {
    py::gil_scoped_release release;
    cases = expand_cohort_inputs(inputs, out);
  }
  py::list taken;
  for (size_t i = 0; i < cases.size(); ++i) {
    if (!shard.takes(i)) continue;
    case_request(cases[i], out, s);  // checks the case's own options
    taken.append(case_dict(cases[i], i));
  }
  py::dict d;
  d["cases"] = taken;
  d["total"] = cases.size();
  d["out_dir"] = out.string();
  d["shard"] = py::make_tuple(shard.index, shard.count);
  return d;
}

py::dict row_dict(const CaseResult& r) {
  py::dict d;
  d["case"] = r.name;
  d["input"] = r.input;
  d["status"] = std::string(case_status_name(r.status));
  d["parts"] = r.parts;
  d["triangles"] = r.triangles;
  d["volume_mm3"] = r.volume_mm3;
  d["seconds"] = r.seconds;
  d["error"] = r.error;
  return d;
}

CaseResult row_from(const py::handle& row) {
  const py::dict d = row.cast<py::dict>();
  CaseResult r{.name = d["case"].cast<std::string>(), .input = d["input"].cast<std::string>()};
  const std::string status = d["status"].cast<std::string>();
  for (CaseStatus s : {CaseStatus::ok, CaseStatus::failed, CaseStatus::skipped, CaseStatus::pending}) {
    if (case_status_name(s) == status) r.status = s;
  }
  if (case_status_name(r.status) != status) {
    throw Error("case " + r.name + ": unknown status \"" + status +
                "\" (ok, failed, skipped or pending)");
  }
  r.parts = d.contains("parts") ? d["parts"].cast<int64_t>() : 0;
  r.triangles = d.contains("triangles") ? d["triangles"].cast<int64_t>() : 0;
  r.volume_mm3 = d.contains("volume_mm3") ? d["volume_mm3"].cast<double>() : 0;
  r.seconds = d.contains("seconds") ? d["seconds"].cast<double>() : 0;
  r.error = d.contains("error") ? d["error"].cast<std::string>() : "";
  return r;
}

// One case (run_case) with the GIL released; the reader's warnings come back in "warnings".
py::dict run_case_py(const py::object& input, const fs::path& out_dir, const py::object& name,
                     const py::dict& settings, const py::object& callback) {
  const CohortSettings s = settings_from(settings);
  const CohortCase c = case_from(input, name);
  const fs::path out = cohort_output_folder(out_dir);
  CaseRequest q = case_request(c, out, s);
  std::mutex mutex;
  std::vector<std::string> warnings;
  q.read.warn = [&](const std::string& message) {
    std::lock_guard lock(mutex);
    warnings.push_back(message);
  };
  PyProgress progress(callback);
  CaseResult row;
  run_polling(progress, s.threads, [&] {
    std::error_code ec;
    fs::create_directories(out, ec);  // a failure is the case's: run_case reports it
    row = run_case(q, progress);
  });
  py::dict d = row_dict(row);
  d["warnings"] = warnings;
  return d;
}

void write_summary_py(const fs::path& file, const py::list& rows) {
  std::vector<CaseResult> results;
  for (const py::handle& row : rows) results.push_back(row_from(row));
  write_case_summary(file, results);
}

}  // namespace

void add_cohort_functions(py::module_& m) {
  m.def("cohort", &cohort, py::arg("inputs"), py::arg("out_dir"), py::arg("shard"),
        py::arg("settings"));
  m.def("run_case", &run_case_py, py::arg("input"), py::arg("out_dir"), py::arg("name"),
        py::arg("settings"), py::arg("progress"));
  m.def("write_case_summary", &write_summary_py, py::arg("file"), py::arg("rows"));
  m.def("summary_file_name", &summary_file_name, py::arg("shard"), py::arg("shard_count"));
  m.def("remove_case_temporaries", &remove_case_temporaries, py::arg("out_dir"), py::arg("name"));
}

}  // namespace segmesh::python
