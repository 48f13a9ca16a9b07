// Keyword arguments to MeshingOptions, through the options layer's specs (meshing_options.hpp) by
// their command-line names, and the rest of a request (label names, colours, threads).
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "segmesh/label_info.hpp"
#include "segmesh/meshing_options.hpp"

namespace segmesh::python {

namespace py = pybind11;

// Keyword arguments by the CLI's option names (underscores for dashes), parsed by each spec's own
// `set`, so the messages and defaults are the command line's. A flag takes True or False.
MeshingOptions options_from_kwargs(const py::dict& kwargs);

// label_names: a TSV path (the CLI's --label-names) or a dict {label: name or (name, role)}.
std::vector<LabelInfo> label_names_from(const py::object& names);

struct Request {
  MeshingOptions options;  // resolved
  bool measure = true;
  int threads = 0;
};

// Everything a mesh call asks for, checked (segmesh::Error naming the option) before any work.
Request make_request(const py::dict& kwargs, const py::object& label_names,
                     const std::string& color, bool measure, int threads);

}  // namespace segmesh::python
