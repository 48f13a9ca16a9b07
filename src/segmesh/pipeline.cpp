#include "segmesh/pipeline.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>

#include "segmesh/components.hpp"
#include "segmesh/decimation.hpp"
#include "segmesh/error.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/extract_part.hpp"
#include "segmesh/joint_smoothing.hpp"
#include "segmesh/multi_label_dual_contouring.hpp"
#include "segmesh/multi_label_marching_cubes.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string label_list(const std::vector<LabelCount>& counts, size_t max_shown = 20) {
  std::string s;
  size_t shown = 0;
  for (const LabelCount& c : counts) {
    if (c.label == 0) continue;
    if (shown == max_shown) return s + ", ...";
    s += (shown++ ? ", " : "") + std::to_string(c.label);
  }
  return s.empty() ? "none" : s;
}

// The components to mesh, checked against what the volume holds.
template <class T>
Components label_components(const Image& image, const Volume<T>& labels,
                            const MeshingOptions& o, Progress& progress) {
  // One pass over the voxels finds every label's runs; the label counts and the components of the
  // selected labels come from the runs.
  const LabelRuns runs = find_label_runs(labels, progress);
  const auto counts = count_run_labels(runs);
  const bool any_foreground =
      std::any_of(counts.begin(), counts.end(), [](const LabelCount& c) { return c.label != 0; });
  if (!any_foreground) {
    throw Error(image.path + ": no foreground: every voxel is 0; nothing to mesh");
  }
  for (int32_t wanted : o.labels) {
    const bool present = std::any_of(counts.begin(), counts.end(), [&](const LabelCount& c) {
      return c.label == wanted && wanted != 0;
    });
    if (!present) {
      throw Error(image.path + ": label " + std::to_string(wanted) +
                  " is not in the volume (labels present: " + label_list(counts) + ")");
    }
  }
  if (o.labels.empty() && counts.size() > kMaxLabelsWithoutSelection) {
    throw Error(image.path + ": " + std::to_string(counts.size()) +
                " distinct values: this looks like a grey-value image, not a label map; give "
                "--iso VALUE (for bone in CT about 200-300 HU) or choose labels with --labels");
  }
  return join_runs(runs, {.connectivity = o.connectivity, .labels = o.labels});
}

template <class T>
Components iso_components(const Image& image, const Volume<T>& volume, double iso,
                          const MeshingOptions& o, Progress& progress, ValueRange& range) {
  range = value_range(volume);
  Components components = find_components_above(volume, iso, o.connectivity, progress);
  if (components.components.empty()) {
    throw Error(image.path + ": no voxel reaches --iso " + format_number(iso) +
                " (values range from " + format_number(range.min) + " to " +
                format_number(range.max) + ")");
  }
  return components;
}

Part describe_part(const Image& image, const MeshingOptions& o, const Component& c, bool grey) {
  Part part;
  part.label = c.label;
  part.component = c.index;
  part.voxels = c.voxels;
  part.voxel_volume_mm3 = double(c.voxels) * image.grid().voxel_volume();
  std::optional<Rgb> color;
  std::string base;
  if (grey) {
    base = "iso" + format_number(*o.iso);
    part.role = Role::other;
  } else {
    const LabelInfo* info = find_label_info(o.label_names, c.label);
    if (!info) info = find_label_info(image.labels, c.label);
    if (info && !info->name.empty()) {
      base = info->name;
      part.role = info->role.value_or(Role::other);
    } else {
      base = "label" + std::to_string(c.label);
      // The reference data's convention: 1 bone, 2 implant.
      part.role = info && info->role ? *info->role
                  : c.label == 1     ? Role::bone
                  : c.label == 2     ? Role::implant
                                     : Role::other;
    }
    if (info) color = info->color;
  }
  part.name = part_name(base, c.index);
  part.material = default_material(part.role, c.label, color);
  return part;
}

}  // namespace

std::string part_name(std::string_view base, int component) {
  return std::string(base) + "_" + std::to_string(component);
}

void smooth_scene(Scene& scene, const SmoothOptions& options, Progress& progress,
                  ShellOrigins* origin) {
  if (options.method == SmoothMethod::none) return;
  if (scene.surface) {  // one surface for all parts: smoothed once, the shells cut again
    smooth_jointly(*scene.surface, options, progress);
    set_part_shells(scene, origin);
    return;
  }
  // Each part's share of the step is its triangle count; smooth_mesh reports its iterations.
  std::vector<double> weights;
  for (const Part& part : scene.parts) weights.push_back(double(part.mesh.triangle_count()));
  PartsProgress shared(progress, weights);
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    throw_if_cancelled(progress);
    smooth_mesh(scene.parts[p].mesh, options, shared.part(p));
    shared.done(p);
  });
}

void color_scene_by_quality(Scene& scene) {
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    TriMesh& mesh = scene.parts[p].mesh;
    mesh.colors = quality_colors(vertex_quality(mesh));
  });
}

PipelineParts find_parts(const Image& image, const MeshingOptions& options, Progress& progress) {
  const MeshingOptions o = resolve_meshing_options(options);
  const bool grey = o.iso.has_value();
  if (!grey && !image.is_integer()) {
    throw Error(image.path + ": " + image.voxel_type +
                " values are not labels; give --iso VALUE to extract an iso-surface");
  }
  progress.step("components");
  PipelineParts parts;
  std::visit(
      [&](const auto& volume) {
        using T = typename std::decay_t<decltype(volume.voxels)>::value_type;
        if (grey) {
          parts.components = iso_components(image, volume, *o.iso, o, progress, parts.range);
        } else if constexpr (std::is_integral_v<T>) {
          parts.components = label_components(image, volume, o, progress);
        }
      },
      image.volume);
  for (size_t c = 0; c < parts.components.components.size(); ++c) {
    if (parts.components.components[c].voxels >= o.min_voxels) parts.kept.push_back(c);
  }
  if (parts.kept.empty()) {
    throw Error(image.path + ": every component is smaller than --min-voxels " +
                std::to_string(o.min_voxels) + "; lower it");
  }
  parts.touching = !grey && components_touch(parts.components, parts.kept);
  return parts;
}

namespace {

// extract_parts, with the choice to leave a shared surface's shells uncut (parts' meshes empty)
// for a caller that smooths the surface next and cuts them then.
Scene extract_scene(const Image& image, const PipelineParts& parts, const MeshingOptions& options,
                    Progress& progress, int64_t* presmooth_fallbacks, bool cut_shells) {
  const MeshingOptions o = resolve_meshing_options(options);
  const bool grey = o.iso.has_value();
  progress.step(o.method == Method::dual_contouring ? "dual contouring" : "marching cubes");
  Scene scene;
  scene.grid = image.grid();
  scene.parts.resize(parts.kept.size());
  const Components& components = parts.components;
  scene.conforming = o.surfaces == Surfaces::conforming;
  // Parts that touch nowhere are meshed one by one: the same surfaces, without the cost of one.
  if (scene.conforming && parts.touching) {
    for (size_t p = 0; p < parts.kept.size(); ++p) {
      scene.parts[p] = describe_part(image, o, components.components[parts.kept[p]], grey);
    }
    scene.surface =
        o.method == Method::dual_contouring
            ? multi_label_dual_contouring(image.grid(), components, parts.kept,
                                          {.connectivity = o.connectivity, .svd_eps = o.dc_svd_eps},
                                          progress)
            : multi_label_marching_cubes(image.grid(), components, parts.kept, o.connectivity,
                                         progress);
    if (cut_shells) set_part_shells(scene);
    return scene;
  }
  // Each part's share of the step is its voxel count.
  std::vector<double> weights;
  for (size_t c : parts.kept) weights.push_back(double(components.components[c].voxels));
  PartsProgress shared(progress, weights);
  const PartSource source{image, components, parts.range};
  // Dual Contouring's solved neighbourhoods, shared by the parts (dual_contouring.hpp).
  const auto solved = make_shared_neighbourhoods(image.grid(), o);
  std::atomic<int64_t> fallbacks{0};
  tbb::parallel_for(size_t{0}, parts.kept.size(), [&](size_t p) {
    throw_if_cancelled(progress);
    const Component& c = components.components[parts.kept[p]];
    Part part = describe_part(image, o, c, grey);
    PartMesh extracted = extract_part(source, c, o, shared.part(p), solved.get());
    part.mesh = std::move(extracted.mesh);
    if (extracted.unsmoothed_fallback) ++fallbacks;
    scene.parts[p] = std::move(part);
    shared.done(p);
  });
  if (presmooth_fallbacks) *presmooth_fallbacks = fallbacks;
  return scene;
}

}  // namespace

Scene extract_parts(const Image& image, const PipelineParts& parts, const MeshingOptions& options,
                    Progress& progress, int64_t* presmooth_fallbacks) {
  return extract_scene(image, parts, options, progress, presmooth_fallbacks, true);
}

namespace {

// The pipeline. With `release`, the volume's voxels are freed as soon as extraction is done, so
// smoothing and writing do not carry them (build_scene_releasing).
Scene run_pipeline(const Image& image, const MeshingOptions& options, Progress& progress,
                   PipelineStats* timings, ExtractedPositions* extracted, Image* release) {
  const MeshingOptions o = resolve_meshing_options(options);
  PipelineStats local;
  PipelineStats& t = timings ? *timings : local;
  auto start = Clock::now();
  const PipelineParts parts = find_parts(image, o, progress);
  t.dropped_components = static_cast<int64_t>(parts.components.components.size() - parts.kept.size());
  t.parts_touch = parts.touching;
  t.components_ms = ms_since(start);

  start = Clock::now();
  // A shared surface that smoothing changes gets its shells (and their normals) cut once, after.
  const bool smoothed = o.smooth.method != SmoothMethod::none;
  Scene scene = extract_scene(image, parts, o, progress, &t.presmooth_fallbacks, !smoothed);
  // A shared surface's positions before smoothing, gathered into the shells' vertex order once
  // the smoothed surface is cut (the cut depends on the triangles only).
  std::vector<Vec3f> surface_extracted;
  if (extracted) {
    extracted->parts.resize(scene.parts.size());
    if (scene.surface && smoothed) {
      surface_extracted = scene.surface->mesh.positions;
    } else {
      tbb::parallel_for(size_t{0}, scene.parts.size(),
                        [&](size_t p) { extracted->parts[p] = scene.parts[p].mesh.positions; });
    }
  }
  if (release) {
    // Swapped with an empty vector, so the memory goes (`voxels = {}` would only clear it).
    std::visit([](auto& v) { decltype(v.voxels)().swap(v.voxels); }, release->volume);
  }
  t.extract_ms = ms_since(start);

  progress.step("smoothing");
  start = Clock::now();
  ShellOrigins origin;
  smooth_scene(scene, o.smooth, progress, surface_extracted.empty() ? nullptr : &origin);
  if (!surface_extracted.empty()) {
    tbb::parallel_for(size_t{0}, origin.size(), [&](size_t p) {
      std::vector<Vec3f>& positions = extracted->parts[p];
      positions.resize(origin[p].size());
      for (size_t i = 0; i < positions.size(); ++i) positions[i] = surface_extracted[origin[p][i]];
    });
    surface_extracted = {};
  }
  t.smooth_ms = ms_since(start);
  if (o.decimate.active()) {
    progress.step("decimating");
    start = Clock::now();
    if (extracted) {
      for (const Part& part : scene.parts) extracted->undecimated.push_back(part.mesh);
    }
    t.decimation = decimate_scene(scene, o.decimate);
    t.decimate_ms = ms_since(start);
  }
  start = Clock::now();
  if (o.color_by_quality) color_scene_by_quality(scene);
  t.smooth_ms += ms_since(start);
  return scene;
}

}  // namespace

Scene build_scene(const Image& image, const MeshingOptions& options, Progress& progress,
                  PipelineStats* timings, ExtractedPositions* extracted) {
  return run_pipeline(image, options, progress, timings, extracted, nullptr);
}

Scene build_scene_releasing(Image& image, const MeshingOptions& options, Progress& progress,
                            PipelineStats* timings, ExtractedPositions* extracted) {
  return run_pipeline(image, options, progress, timings, extracted, &image);
}

}  // namespace segmesh
