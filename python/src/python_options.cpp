#include "python_options.hpp"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <utility>

#include "segmesh/error.hpp"
#include "segmesh_io/label_names.hpp"

namespace segmesh::python {

namespace fs = std::filesystem;

MeshingOptions options_from_kwargs(const py::dict& kwargs) {
  MeshingOptions options;
  for (const auto& [key, value] : kwargs) {
    std::string name = py::str(key);
    for (char& c : name) c = c == '_' ? '-' : c;
    const MeshingOptionSpec* spec = find_meshing_option(name);
    if (!spec) {
      throw Error("unknown option " + std::string(py::str(key)) + " (--" + name +
                  " is not an option of segmesh mesh; segmesh.options() lists them)");
    }
    if (value.is_none()) continue;
    const bool is_bool = py::isinstance<py::bool_>(value);
    if (spec->is_flag()) {
      if (!is_bool) throw Error("--" + name + " is a flag: give True or False");
      spec->set(options, value.cast<bool>() ? "true" : "false");
      continue;
    }
    if (is_bool) throw Error("--" + name + " takes " + std::string(spec->type_name) + ", not True/False");
    std::string text;
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
      for (const auto& item : value) {
        if (!text.empty()) text += ',';
        text += std::string(py::str(item));
      }
    } else {
      text = py::str(value);
    }
    spec->set(options, text);
  }
  return options;
}

namespace {

std::vector<LabelInfo> label_names_from_object(const py::object& names) {
  if (!py::isinstance<py::dict>(names)) return read_label_names(names.cast<fs::path>());
  std::vector<LabelInfo> out;
  for (const auto& [key, value] : names.cast<py::dict>()) {
    LabelInfo info;
    info.label = key.cast<int32_t>();
    if (py::isinstance<py::str>(value)) {
      info.name = value.cast<std::string>();
    } else {
      const auto pair = value.cast<std::pair<std::string, std::string>>();
      info.name = pair.first;
      info.role = parse_role(pair.second);
      if (!info.role) {
        throw Error("label_names: label " + std::to_string(info.label) + ": unknown role \"" +
                    pair.second + "\" (use bone, implant or other)");
      }
    }
    out.push_back(std::move(info));
  }
  return out;
}

}  // namespace

std::vector<LabelInfo> label_names_from(const py::object& names) {
  if (names.is_none()) return {};
  try {
    return label_names_from_object(names);
  } catch (const py::cast_error&) {
    throw Error("label_names must be a TSV file (the CLI's --label-names) or a dict {label: name} "
                "or {label: (name, role)} with whole-number labels and text names (got " +
                std::string(py::repr(names)).substr(0, 80) + ")");
  }
}

Request make_request(const py::dict& kwargs, const py::object& label_names,
                     const std::string& color, bool measure, int threads) {
  Request r;
  r.options = options_from_kwargs(kwargs);
  r.options.label_names = label_names_from(label_names);
  r.options = resolve_meshing_options(r.options);
  if (color != "material" && color != "quality") {
    throw Error("--color must be material or quality (got \"" + color + "\")");
  }
  r.options.color_by_quality = color == "quality";
  if (threads < 0) throw Error("--threads must be 0 (all cores) or more");
  r.measure = measure;
  r.threads = threads;
  return r;
}

}  // namespace segmesh::python
