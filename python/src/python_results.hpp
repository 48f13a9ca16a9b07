// The results handed to Python: a scene's parts as dicts of numpy arrays over the core's own
// buffers (no copy) with the report's numbers (measure_scene), and parts given back by Python as a
// Scene for the writers.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "segmesh/pipeline.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/scene_measures.hpp"

namespace segmesh::python {

namespace py = pybind11;

// {parts: [...], contacts: [...], conforming, dropped_components, timings}; moves the meshes out
// of `scene`. GIL held.
py::dict result_dict(Scene&& scene, const SceneMeasures& measures, const PipelineStats& stats);

// Writes parts given as dicts (name, label, role, vertices, faces, normals, color, ...): one file,
// or one file per part when `path` ends with '/' or is a folder, as `segmesh mesh -o` does.
// Returns the files written.
// quantize: KHR_mesh_quantization (glb only), as `segmesh mesh --quantize`.
std::vector<std::string> write_parts_py(const py::list& parts, const std::string& path,
                                        const std::string& format, bool quantize);

}  // namespace segmesh::python
