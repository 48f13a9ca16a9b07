// _segmesh: the Python module behind the `segmesh` package (python/segmesh/__init__.py). It has no
// meshing logic of its own: an array becomes an Image (checked by check_volume_geometry, the
// readers' own checks), keyword options go through the options layer's specs by their
// command-line names, build_scene meshes, measure_scene gives the report's numbers, and the
// writers of segmesh_io write. The GIL is released while the volume is copied, meshed and
// measured; a progress callback and Ctrl-C (KeyboardInterrupt) cancel through segmesh::Progress.
// The pieces: python_options (keyword arguments), python_arrays (arrays to Image), python_results
// (scenes to dicts of numpy arrays, and back for the writers), python_progress (the run on its own
// thread and its progress), python_cohort (the cohort case runner: run_case and the rest).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "python_arrays.hpp"
#include "python_cohort.hpp"
#include "python_options.hpp"
#include "python_progress.hpp"
#include "python_results.hpp"
#include "segmesh/error.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/read_volume.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace segmesh;
using namespace segmesh::python;

namespace {

// Meshes and measures `make_image()`'s image on a thread of its own, the GIL released, while the
// calling thread polls `progress` (Ctrl-C, the callback); raises the Python error that cancelled
// the run, or segmesh.Cancelled, or the core's error.
template <class MakeImage>
py::dict run(const Request& request, const py::object& callback, MakeImage&& make_image) {
  PyProgress progress(callback);
  Scene scene;
  SceneMeasures measures;
  PipelineStats stats;
  run_polling(progress, request.threads, [&] {
    Image image = make_image();
    const SmoothOptions& s = request.options.smooth;
    const bool moved = s.method != SmoothMethod::none || request.options.decimate.active();
    ExtractedPositions extracted;
    scene = build_scene_releasing(image, request.options, progress, &stats,
                                  request.measure && moved ? &extracted : nullptr);
    if (request.measure) {
      measures = measure_scene(
          scene, {.quality = true, .contacts = true, .extracted = moved ? &extracted : nullptr},
          progress);
    }
  });
  return result_dict(std::move(scene), measures, stats);
}

py::dict mesh_array(const py::object& labels, std::array<double, 3> spacing,
                    std::array<double, 3> origin, std::array<double, 9> direction,
                    const py::object& label_names, const std::string& color, bool measure,
                    const py::object& progress, int threads, uint64_t max_voxels,
                    const py::dict& kwargs) {
  const Request request = make_request(kwargs, label_names, color, measure, threads);
  const ArrayInput in = check_array(labels, spacing, origin, direction, max_voxels);
  return run(request, progress, [&] {
    Image image;
    image.path = "array";
    image.voxel_type = in.dtype;
    image.volume = volume_from(in);
    return image;
  });
}

py::dict mesh_file(const fs::path& path, const py::object& label_names, const std::string& color,
                   bool measure, const py::object& progress, int threads, uint64_t max_voxels,
                   const py::dict& kwargs) {
  const Request request = make_request(kwargs, label_names, color, measure, threads);
  std::vector<std::string> warnings;
  py::dict result = run(request, progress, [&] {
    ReadOptions read{.max_voxels = max_voxels,
                     .warn = [&](const std::string& message) { warnings.push_back(message); }};
    return read_volume(path, read);
  });
  result["warnings"] = warnings;
  return result;
}

py::list option_specs() {
  py::list out;
  const MeshingOptions defaults;
  for (const MeshingOptionSpec& spec : meshing_option_specs()) {
    py::dict d;
    d["name"] = std::string(spec.name);
    d["keyword"] = [&] {
      std::string k(spec.name);
      for (char& c : k) c = c == '-' ? '_' : c;
      return k;
    }();
    d["type"] = std::string(spec.type_name);
    d["help"] = std::string(spec.help);
    d["default"] = spec.get(defaults);
    out.append(d);
  }
  return out;
}

// The built-in phantom (phantom.hpp) as a Fortran-ordered int32 array indexed [i, j, k], without
// a copy, and its spacing.
py::tuple phantom(std::array<int64_t, 3> size, std::array<double, 3> spacing) {
  LabelVolume volume;
  {
    py::gil_scoped_release release;
    volume = make_phantom({.size = size, .spacing = spacing});
  }
  auto* owner = new std::vector<int32_t>(std::move(volume.voxels));
  py::capsule capsule(owner, [](void* p) { delete static_cast<std::vector<int32_t>*>(p); });
  const auto& d = volume.grid.dims;
  const py::ssize_t e = sizeof(int32_t);
  py::array_t<int32_t> array({d[0], d[1], d[2]}, {e, e * d[0], e * d[0] * d[1]}, owner->data(),
                             capsule);
  return py::make_tuple(array, volume.grid.spacing);
}

}  // namespace

PYBIND11_MODULE(_segmesh, m) {
  m.doc() = "segmesh's C++ core; use the segmesh package, not this module";
  static py::exception<Cancelled> cancelled(m, "Cancelled", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Cancelled& e) {
      cancelled(e.what());
    } catch (const Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.def("mesh_array", &mesh_array, py::arg("labels"), py::arg("spacing"), py::arg("origin"),
        py::arg("direction"), py::arg("label_names"), py::arg("color"), py::arg("measure"),
        py::arg("progress"), py::arg("threads"), py::arg("max_voxels"), py::arg("options"));
  m.def("mesh_file", &mesh_file, py::arg("path"), py::arg("label_names"), py::arg("color"),
        py::arg("measure"), py::arg("progress"), py::arg("threads"), py::arg("max_voxels"),
        py::arg("options"));
  m.def("write", &write_parts_py, py::arg("parts"), py::arg("path"), py::arg("format"),
        py::arg("quantize") = false);
  m.def("option_specs", &option_specs);
  m.def("phantom", &phantom, py::arg("size"), py::arg("spacing"));
  add_cohort_functions(m);
}

