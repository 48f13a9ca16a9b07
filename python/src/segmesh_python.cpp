// _segmesh: the Python module behind the `segmesh` package (python/segmesh/__init__.py). It has no
// meshing logic of its own: an array becomes an Image (checked by check_volume_geometry, the
// readers' own checks), keyword options go through the options layer's specs by their
// command-line names, build_scene meshes, measure_scene gives the report's numbers, and the
// writers of segmesh_io write. The GIL is released while the volume is copied, meshed and
// measured; a progress callback and Ctrl-C (KeyboardInterrupt) cancel through segmesh::Progress.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/label_names.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace segmesh;

namespace {

// ---- options -------------------------------------------------------------------------------

// Keyword arguments by the CLI's option names (underscores for dashes), parsed by each spec's own
// `set`, so the messages and defaults are the command line's. A flag takes True or False.
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
      for (const auto& item : value) text += (text.empty() ? "" : ",") + std::string(py::str(item));
    } else {
      text = py::str(value);
    }
    spec->set(options, text);
  }
  return options;
}

// label_names: a TSV path (the CLI's --label-names) or a dict {label: name or (name, role)}.
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

// ---- progress and cancellation ---------------------------------------------------------------

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
    }
  }

  // With the GIL held, after the core threw Cancelled: the Python error that cancelled, if any.
  bool restore_error() {
    if (!error_type_) return false;
    PyErr_Restore(error_type_, error_value_, error_trace_);
    error_type_ = error_value_ = error_trace_ = nullptr;
    return true;
  }

 private:
  void call(const std::string& step, double fraction) {
    const py::object result = callback_(step, fraction);
    if (!result.is_none() && !result.cast<bool>()) cancelled_.store(true);
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
};

// ---- arrays -> Image -----------------------------------------------------------------------

std::string shape_text(const py::buffer_info& info) {
  std::string text;
  for (py::ssize_t d : info.shape) text += (text.empty() ? "" : "x") + std::to_string(d);
  return text;
}

// The voxels of a 3-D strided array indexed [i, j, k] as segmesh stores them (i fastest): one
// copy, a plain memcpy when the array is Fortran-ordered (as nibabel's are).
template <class Out, class In>
std::vector<Out> copy_voxels(const py::buffer_info& info, const std::array<int64_t, 3>& dims) {
  std::vector<Out> out(static_cast<size_t>(dims[0] * dims[1] * dims[2]));
  const auto* base = static_cast<const char*>(info.ptr);
  const py::ssize_t s0 = info.strides[0], s1 = info.strides[1], s2 = info.strides[2];
  if (std::is_same_v<In, Out> && s0 == py::ssize_t(sizeof(In)) && s1 == s0 * dims[0] &&
      s2 == s1 * dims[1]) {
    std::memcpy(out.data(), base, out.size() * sizeof(Out));
    return out;
  }
  const auto load = [](const char* p) {
    In v;
    std::memcpy(&v, p, sizeof(In));
    return static_cast<Out>(v);
  };
  if (std::abs(s0) <= std::abs(s2)) {
    // i is the array's faster axis (Fortran-like): rows of i copied one by one.
    tbb::parallel_for(int64_t{0}, dims[2], [&](int64_t k) {
      for (int64_t j = 0; j < dims[1]; ++j) {
        Out* row = out.data() + (k * dims[1] + j) * dims[0];
        const char* src = base + k * s2 + j * s1;
        for (int64_t i = 0; i < dims[0]; ++i) row[i] = load(src + i * s0);
      }
    });
    return out;
  }
  // k is the faster axis (C order, numpy's and torch's default): a transpose, in blocks of 64 k
  // so that reads run along k and the 64 rows written stay in cache.
  constexpr int64_t kBlock = 64;
  tbb::parallel_for(int64_t{0}, dims[1], [&](int64_t j) {
    for (int64_t k0 = 0; k0 < dims[2]; k0 += kBlock) {
      const int64_t k1 = std::min(dims[2], k0 + kBlock);
      for (int64_t i = 0; i < dims[0]; ++i) {
        const char* src = base + i * s0 + j * s1;
        for (int64_t k = k0; k < k1; ++k) out[size_t((k * dims[1] + j) * dims[0] + i)] = load(src + k * s2);
      }
    }
  });
  return out;
}

template <class Out, class In>
AnyVolume make_volume(const py::buffer_info& info, const Grid& grid) {
  return Volume<Out>{grid, copy_voxels<Out, In>(info, grid.dims)};
}

// How an array's dtype is held by the core: integer label maps in uint8, int16, uint16 or int32
// (bool and int8 widened), floating point as float (for --iso). Decided with the GIL held.
enum class Held { u8, i8_to_i16, i16, u16, i32, f32, f64_to_f32 };

Held held_type(const py::array& array) {
  const char kind = array.dtype().kind();
  const py::ssize_t size = array.itemsize();
  if (kind == 'b' || (kind == 'u' && size == 1)) return Held::u8;
  if (kind == 'i' && size == 1) return Held::i8_to_i16;
  if (kind == 'i' && size == 2) return Held::i16;
  if (kind == 'u' && size == 2) return Held::u16;
  if (kind == 'i' && size == 4) return Held::i32;
  if (kind == 'f' && size == 4) return Held::f32;
  if (kind == 'f' && size == 8) return Held::f64_to_f32;
  throw Error("array: dtype " + std::string(py::str(array.dtype())) +
              " is not supported; give uint8, uint16, int16 or int32 labels, or float32/float64 "
              "grey values with iso");
}

// The voxels, copied (no Python call: runs without the GIL).
AnyVolume volume_from(Held held, const py::buffer_info& info, const Grid& grid) {
  switch (held) {
    case Held::u8: return make_volume<uint8_t, uint8_t>(info, grid);
    case Held::i8_to_i16: return make_volume<int16_t, int8_t>(info, grid);
    case Held::i16: return make_volume<int16_t, int16_t>(info, grid);
    case Held::u16: return make_volume<uint16_t, uint16_t>(info, grid);
    case Held::i32: return make_volume<int32_t, int32_t>(info, grid);
    case Held::f32: return make_volume<float, float>(info, grid);
    case Held::f64_to_f32: return make_volume<float, double>(info, grid);
  }
  throw std::logic_error("unknown held type");
}

struct ArrayInput {
  py::array array;
  py::buffer_info info;
  Grid grid;
  Held held = Held::u8;
  std::string dtype;
};

ArrayInput check_array(const py::object& labels, const std::array<double, 3>& spacing,
                       const std::array<double, 3>& origin, const std::array<double, 9>& direction,
                       uint64_t max_voxels) {
  if (!py::isinstance<py::array>(labels)) {
    throw Error("array: expected a numpy array, got " +
                std::string(py::str(labels.get_type().attr("__name__"))));
  }
  ArrayInput in{labels.cast<py::array>(), {}, {}};
  in.info = in.array.request();
  in.dtype = py::str(in.array.dtype());
  for (py::ssize_t d : in.info.shape) {
    if (d == 0) throw Error("array: empty (shape " + shape_text(in.info) + "); nothing to mesh");
  }
  in.grid.spacing = spacing;
  in.grid.origin = origin;
  in.grid.direction = Mat3d{direction[0], direction[1], direction[2], direction[3], direction[4],
                            direction[5], direction[6], direction[7], direction[8]};
  const std::vector<int64_t> dims(in.info.shape.begin(), in.info.shape.end());
  in.grid.dims = check_volume_geometry("array", dims, in.grid, {.max_voxels = max_voxels});
  in.held = held_type(in.array);
  return in;
}

// ---- meshing -------------------------------------------------------------------------------

struct Request {
  MeshingOptions options;
  bool measure = true;
  int threads = 0;
};

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

py::dict deviation_dict(const Deviation& d) {
  py::dict out;
  out["hausdorff_mm"] = d.hausdorff;
  out["mean_mm"] = d.mean;
  out["p95_mm"] = d.p95;
  return out;
}

py::dict measures_dict(const PartMeasures& m) {
  py::dict out;
  out["vertices"] = m.mesh.vertices;
  out["triangles"] = m.mesh.triangles;
  out["area_mm2"] = m.mesh.area_mm2;
  out["volume_mm3"] = m.mesh.volume_mm3;
  out["closed"] = m.mesh.closed();
  out["boundary_edges"] = m.mesh.boundary_edges;
  out["nonmanifold_edges"] = m.mesh.nonmanifold_edges;
  out["nonmanifold_vertices"] = m.mesh.nonmanifold_vertices;
  out["winding_errors"] = m.mesh.winding_errors;
  out["degenerate_triangles"] = m.mesh.degenerate_triangles;
  out["shells"] = m.mesh.shells;
  out["euler"] = m.mesh.euler;
  out["mean_edge_length_mm"] = m.mesh.mean_edge_length_mm;
  if (m.quality) {
    py::dict q;
    q["min"] = m.quality->min;
    q["mean"] = m.quality->mean;
    q["p01"] = m.quality->p01;
    q["histogram"] = m.quality->histogram;
    out["quality"] = q;
  }
  if (m.volume_before_mm3) out["volume_before_smoothing_mm3"] = *m.volume_before_mm3;
  if (m.smoothing_deviation) out["smoothing_deviation"] = deviation_dict(*m.smoothing_deviation);
  if (m.triangles_before_decimation) out["triangles_before_decimation"] = *m.triangles_before_decimation;
  if (m.decimation_deviation) out["decimation_deviation"] = deviation_dict(*m.decimation_deviation);
  return out;
}

// A vector handed to numpy without a copy: the array owns it through a capsule.
template <class T, class Elem>
py::array owned_array(std::vector<T>&& values, size_t columns) {
  auto* owner = new std::vector<T>(std::move(values));
  py::capsule capsule(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  const size_t rows = owner->size() * sizeof(T) / (sizeof(Elem) * columns);
  return py::array_t<Elem>({rows, columns}, reinterpret_cast<Elem*>(owner->data()), capsule);
}

py::dict result_dict(Scene&& scene, const SceneMeasures& measures, const PipelineStats& stats) {
  py::list parts;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    Part& part = scene.parts[p];
    if (part.mesh.vertex_count() > size_t(INT32_MAX)) {
      throw Error(part.name + ": more than 2^31 vertices do not fit int32 faces");
    }
    py::dict d;
    d["name"] = part.name;
    d["label"] = part.label;
    d["component"] = part.component;
    d["role"] = std::string(role_name(part.role));
    d["voxels"] = part.voxels;
    d["voxel_volume_mm3"] = part.voxel_volume_mm3;
    d["color"] = std::array<float, 3>{part.material.base_color.r, part.material.base_color.g,
                                      part.material.base_color.b};
    d["metallic"] = part.material.metallic;
    d["roughness"] = part.material.roughness;
    d["vertices"] = owned_array<Vec3f, float>(std::move(part.mesh.positions), 3);
    d["faces"] = owned_array<uint32_t, int32_t>(std::move(part.mesh.indices), 3);
    d["normals"] = owned_array<Vec3f, float>(std::move(part.mesh.normals), 3);
    if (!part.mesh.colors.empty()) {
      d["colors"] = owned_array<Rgba8, uint8_t>(std::move(part.mesh.colors), 4);
    }
    if (p < measures.parts.size()) d["measures"] = measures_dict(measures.parts[p]);
    parts.append(d);
  }
  py::list contacts;
  for (const ContactMeasures& c : measures.contacts) {
    py::dict d;
    d["a"] = c.a;
    d["b"] = c.b;
    d["area_mm2"] = c.area_mm2;
    d["max_gap_mm"] = c.max_gap_mm;
    contacts.append(d);
  }
  py::dict timings;
  timings["components_ms"] = stats.components_ms;
  timings["extract_ms"] = stats.extract_ms;
  timings["smooth_ms"] = stats.smooth_ms;
  timings["decimate_ms"] = stats.decimate_ms;
  py::dict out;
  out["parts"] = parts;
  out["contacts"] = contacts;
  out["conforming"] = scene.conforming;
  out["dropped_components"] = stats.dropped_components;
  out["timings"] = timings;
  return out;
}

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
  return result_dict(std::move(scene), measures, stats);
}

py::dict mesh_array(const py::object& labels, std::array<double, 3> spacing,
                    std::array<double, 3> origin, std::array<double, 9> direction,
                    const py::object& label_names, const std::string& color, bool measure,
                    const py::object& progress, int threads, uint64_t max_voxels,
                    const py::dict& kwargs) {
  const Request request = make_request(kwargs, label_names, color, measure, threads);
  ArrayInput in = check_array(labels, spacing, origin, direction, max_voxels);
  return run(request, progress, [&] {
    Image image;
    image.path = "array";
    image.voxel_type = in.dtype;
    image.volume = volume_from(in.held, in.info, in.grid);
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

// ---- writing -------------------------------------------------------------------------------

template <class T>
std::vector<T> rows_of(const py::handle& value, size_t columns, const std::string& what) {
  const auto array = py::array_t<typename T::value_type, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 2 || size_t(array.shape(1)) != columns) {
    throw Error(what + " must be an N x " + std::to_string(columns) + " array");
  }
  std::vector<T> out(size_t(array.shape(0)));
  std::memcpy(out.data(), array.data(), out.size() * sizeof(T));
  return out;
}

// Writes parts given as dicts (name, label, role, vertices, faces, normals, color, ...): one file,
// or one file per part when `path` ends with '/' or is a folder, as `segmesh mesh -o` does.
std::vector<std::string> write_parts_py(const py::list& parts, const std::string& path,
                                        const std::string& format) {
  Scene scene;
  for (const auto& item : parts) {
    const py::dict d = item.cast<py::dict>();
    Part part;
    part.name = d["name"].cast<std::string>();
    part.label = d["label"].cast<int32_t>();
    const auto role = parse_role(d["role"].cast<std::string>());
    if (!role) throw Error(part.name + ": unknown role; use bone, implant or other");
    part.role = *role;
    std::optional<Rgb> color;
    if (d.contains("color")) {
      const auto c = d["color"].cast<std::array<float, 3>>();
      color = Rgb{c[0], c[1], c[2]};
    }
    part.material = default_material(part.role, part.label, color);
    if (d.contains("metallic")) part.material.metallic = d["metallic"].cast<float>();
    if (d.contains("roughness")) part.material.roughness = d["roughness"].cast<float>();
    using Vec = std::array<float, 3>;
    using Tri = std::array<uint32_t, 3>;
    for (const Vec& v : rows_of<Vec>(d["vertices"], 3, part.name + ": vertices")) {
      part.mesh.positions.push_back({v[0], v[1], v[2]});
    }
    for (const Tri& t : rows_of<Tri>(d["faces"], 3, part.name + ": faces")) {
      for (uint32_t id : t) {
        if (id >= part.mesh.positions.size()) {
          throw Error(part.name + ": a face names vertex " + std::to_string(id) + " of " +
                      std::to_string(part.mesh.positions.size()));
        }
        part.mesh.indices.push_back(id);
      }
    }
    if (d.contains("normals") && !d["normals"].is_none()) {
      for (const Vec& n : rows_of<Vec>(d["normals"], 3, part.name + ": normals")) {
        part.mesh.normals.push_back({n[0], n[1], n[2]});
      }
      if (part.mesh.normals.size() != part.mesh.positions.size()) part.mesh.normals.clear();
    }
    scene.parts.push_back(std::move(part));
  }
  const bool folder = (!path.empty() && path.back() == '/') || fs::is_directory(path);
  std::optional<MeshFormat> chosen;
  if (!format.empty()) {
    chosen = parse_mesh_format(format);
    if (!chosen) throw Error("--format must be stl, ply, obj or glb (got \"" + format + "\")");
  }
  py::gil_scoped_release release;
  if (folder) {
    std::vector<std::string> out;
    fs::path dir = path;
    if (path.back() == '/') dir = dir.parent_path();
    for (const fs::path& p : write_parts(scene, dir, chosen.value_or(MeshFormat::ply))) {
      out.push_back(p.string());
    }
    return out;
  }
  const auto by_name = mesh_format_from_path(path);
  if (!by_name) {
    throw Error(path + ": unknown mesh format \"" + fs::path(path).extension().string() +
                "\"; use .stl, .ply, .obj or .glb, or end the path with / for one file per part");
  }
  if (chosen && *chosen != *by_name) throw Error(path + ": format " + format + " disagrees with the file extension");
  write_scene(scene, path, *by_name);
  return {path};
}

// ---- the rest ------------------------------------------------------------------------------

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
  m.def("write", &write_parts_py, py::arg("parts"), py::arg("path"), py::arg("format"));
  m.def("option_specs", &option_specs);
  m.def("phantom", &phantom, py::arg("size"), py::arg("spacing"));
}
