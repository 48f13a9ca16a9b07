// _segmesh: the Python module behind the `segmesh` package (python/segmesh/__init__.py). It has no
// meshing logic of its own: an array becomes an Image (checked by check_volume_geometry, the
// readers' own checks), keyword options go through the options layer's specs by their
// command-line names, build_scene meshes, measure_scene gives the report's numbers, and the
// writers of segmesh_io write. The GIL is released while the volume is copied, meshed and
// measured; a progress callback and Ctrl-C (KeyboardInterrupt) cancel through segmesh::Progress.
// The pieces: python_options (keyword arguments), python_arrays (arrays to Image), python_results
// (scenes to dicts of numpy arrays, and back for the writers).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/global_control.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "python_arrays.hpp"
#include "python_options.hpp"
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

// The core reports from any thread; Python is called only from the calling thread, which waits
// for the run (on its own thread) and every 50 ms, with the GIL taken, checks for Ctrl-C
// (PyErr_CheckSignals: Python runs signal handlers on its main thread only) and calls the
// callback with the current step and fraction. A callback that returns False or raises, and
// KeyboardInterrupt, cancel the run; the Python error is kept and raised once the core unwound.
class PyProgress : public Progress {
 public:
  explicit PyProgress(py::object callback) : callback_(std::move(callback)) {}
  ~PyProgress() override {
    Py_XDECREF(error_type_);
    Py_XDECREF(error_value_);
    Py_XDECREF(error_trace_);
  }

  void step(std::string_view name) override {
    std::lock_guard lock(step_mutex_);
    step_ = name;
    begun_.push_back(step_);
    fraction_.store(0, std::memory_order_relaxed);
  }
  void update(double fraction) override { fraction_.store(fraction, std::memory_order_relaxed); }
  bool cancelled() const override { return cancelled_.load(std::memory_order_relaxed); }

  // On the calling thread, with the GIL held.
  void poll() {
    if (cancelled_.load()) return;
    if (PyErr_CheckSignals() != 0) return cancel_with_python_error();
    if (callback_.is_none()) return;
    // Every step is reported, with fraction 0, also one that began and ended since the last poll;
    // then the current step with its fraction.
    std::vector<std::string> begun;
    std::string step;
    {
      std::lock_guard lock(step_mutex_);
      begun.swap(begun_);
      step = step_;
    }
    if (step.empty()) return;
    try {
      for (size_t i = 0; i + 1 < begun.size() && !cancelled_.load(); ++i) call(begun[i], 0);
      if (!cancelled_.load()) call(step, fraction_.load(std::memory_order_relaxed));
    } catch (py::error_already_set& e) {
      e.restore();
      cancel_with_python_error();
    } catch (...) {  // nothing may leave the polling loop while the run goes on
      other_error_ = std::current_exception();
      cancelled_.store(true);
    }
  }

  // On the calling thread, with the GIL held, after a run that was not cancelled: the steps not
  // reported yet (a run shorter than one poll), then the last step at 1. The callback's error, if
  // it raises, is raised.
  void finish() {
    if (callback_.is_none() || cancelled_.load()) return;
    std::vector<std::string> begun;
    std::string step;
    {
      std::lock_guard lock(step_mutex_);
      begun.swap(begun_);
      step = step_;
    }
    for (size_t i = 0; i + 1 < begun.size(); ++i) call(begun[i], 0);
    if (!step.empty()) call(step, 1);
  }

  // With the GIL held, after the core threw Cancelled: raises what cancelled the run, if it was
  // an error (the callback's or KeyboardInterrupt); returns false when the callback said stop.
  bool restore_error() {
    if (other_error_) std::rethrow_exception(other_error_);
    if (!error_type_) return false;
    PyErr_Restore(error_type_, error_value_, error_trace_);
    error_type_ = error_value_ = error_trace_ = nullptr;
    return true;
  }

 private:
  void call(const std::string& step, double fraction) {
    const py::object result = callback_(step, fraction);
    if (result.is_none()) return;
    const int truth = PyObject_IsTrue(result.ptr());
    if (truth < 0) throw py::error_already_set();
    if (truth == 0) cancelled_.store(true);
  }

  void cancel_with_python_error() {
    PyErr_Fetch(&error_type_, &error_value_, &error_trace_);
    cancelled_.store(true);
  }

  py::object callback_;
  std::atomic<bool> cancelled_{false};
  std::atomic<double> fraction_{0};
  std::mutex step_mutex_;
  std::string step_;
  std::vector<std::string> begun_;  // steps begun since the last poll
  PyObject* error_type_ = nullptr;
  PyObject* error_value_ = nullptr;
  PyObject* error_trace_ = nullptr;
  std::exception_ptr other_error_;
};

// Meshes and measures `make_image()`'s image on a thread of its own, the GIL released, while the
// calling thread polls `progress` (Ctrl-C, the callback); raises the Python error that cancelled
// the run, or segmesh.Cancelled, or the core's error.
template <class MakeImage>
py::dict run(const Request& request, const py::object& callback, MakeImage&& make_image) {
  PyProgress progress(callback);
  Scene scene;
  SceneMeasures measures;
  PipelineStats stats;
  std::exception_ptr error;
  {
    py::gil_scoped_release release;
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::thread worker([&] {
      try {
        std::unique_ptr<tbb::global_control> limit;
        if (request.threads > 0) {
          limit = std::make_unique<tbb::global_control>(
              tbb::global_control::max_allowed_parallelism, size_t(request.threads));
        }
        Image image = make_image();
        const SmoothOptions& s = request.options.smooth;
        const bool moved = s.method != SmoothMethod::none || request.options.decimate.active();
        ExtractedPositions extracted;
        scene = build_scene_releasing(image, request.options, progress, &stats,
                                      request.measure && moved ? &extracted : nullptr);
        if (request.measure) {
          measures = measure_scene(scene, {.quality = true,
                                           .contacts = true,
                                           .extracted = moved ? &extracted : nullptr},
                                   progress);
        }
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard lock(mutex);
      done = true;
      finished.notify_one();
    });
    std::unique_lock lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        progress.poll();
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (error) {
    try {
      std::rethrow_exception(error);
    } catch (const Cancelled&) {
      if (progress.restore_error()) throw py::error_already_set();
      throw;
    }
  }
  // Cancelled after the core's last check (Ctrl-C during the last moments): the run is complete,
  // but the interrupt is not swallowed, and a callback's stop is honoured the same way.
  if (progress.cancelled()) {
    if (progress.restore_error()) throw py::error_already_set();
    throw Cancelled();
  }
  progress.finish();
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
}

