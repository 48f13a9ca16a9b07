// The cohort case runner from Python (docs/PYTHON.md, docs/COHORTS.md): the library's
// expand_cohort_inputs, case_options, run_case and write_case_summary behind plain Python data
// (dicts of text and numbers, which pickle, so a Dask scheduler can ship them to its workers). No
// logic of its own beyond turning keyword arguments into a CaseRequest as `segmesh batch` does.
#pragma once

#include <pybind11/pybind11.h>

namespace segmesh::python {

namespace py = pybind11;

// Adds cohort, run_case, write_case_summary, summary_file_name and remove_case_temporaries.
void add_cohort_functions(py::module_& m);

}  // namespace segmesh::python
