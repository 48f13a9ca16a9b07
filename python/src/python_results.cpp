#include "python_results.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <climits>
#include <cstring>
#include <filesystem>
#include <optional>

#include "segmesh/error.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh::python {

namespace fs = std::filesystem;

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

std::vector<std::string> write_parts_py(const py::list& parts, const std::string& path,
                                        const std::string& format, bool quantize) {
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
  const MeshWriteOptions options{.quantize = quantize};
  const MeshTarget target = resolve_mesh_target(path, format, options);
  py::gil_scoped_release release;
  if (target.folder) {
    std::vector<std::string> out;
    for (const fs::path& p : write_parts(scene, target.path, target.format, options)) {
      out.push_back(p.string());
    }
    return out;
  }
  write_scene(scene, target.path, target.format, options);
  return {path};
}

}  // namespace segmesh::python
