// segmesh study INPUT -o DIR: reproduces the reference thesis's evaluation (its Tables 1-3) on any
// input and writes DIR/study.md, DIR/study.json, colour-coded meshes (radii ratio, blue 0 to
// green 1) as GLB and pictures of the meshes (PNG, rendered headless by segmesh_render).
//   Table 1: Marching Cubes against Dual Contouring — vertices, triangles, time.
//   Table 2: smoothing — volume change and deviation from the unsmoothed surface, time.
//   Table 3: triangle quality — minimum and mean radii ratio with and without smoothing.
// Every mesh comes from the pipeline (build_scene, smooth_scene), as in `segmesh mesh`.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "progress_bar.hpp"
#include "segmesh/error.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/label_names.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/headless_context.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct StudyArgs {
  std::string input;
  std::string output;
  std::vector<int32_t> labels;
  std::optional<double> iso;
  std::string label_names;
  int threads = 0;
  bool quiet = false;
  ReadArgs read;
};

// All parts of a scene as one mesh (for scene-wide deviation and quality).
TriMesh merged(const Scene& scene) {
  TriMesh all;
  for (const Part& p : scene.parts) {
    const uint32_t base = static_cast<uint32_t>(all.positions.size());
    all.positions.insert(all.positions.end(), p.mesh.positions.begin(), p.mesh.positions.end());
    for (uint32_t i : p.mesh.indices) all.indices.push_back(base + i);
  }
  return all;
}

// The mesh in voxel units (index space: origin, direction and spacing undone). Radii ratios there
// say how well the triangles fit the voxel grid whatever its anisotropy — what a tool that meshes in
// voxel units and scales afterwards reports.
TriMesh in_voxel_units(const TriMesh& m, const Grid& g) {
  TriMesh out = m;
  const Mat3d& d = g.direction;
  for (Vec3f& p : out.positions) {
    const Vec3d w{p.x - g.origin[0], p.y - g.origin[1], p.z - g.origin[2]};
    // direction is orthonormal: its inverse is its transpose.
    const Vec3d r{d[0] * w.x + d[3] * w.y + d[6] * w.z, d[1] * w.x + d[4] * w.y + d[7] * w.z,
                  d[2] * w.x + d[5] * w.y + d[8] * w.z};
    p = to_float({r.x / g.spacing[0], r.y / g.spacing[1], r.z / g.spacing[2]});
  }
  return out;
}

double scene_volume(const Scene& scene) {
  double v = 0;
  for (const Part& p : scene.parts) v += enclosed_volume(p.mesh);
  return v;
}

struct Extraction {
  std::string name;
  Scene scene;
  TriMesh all;
  double ms = 0;
};

struct SmoothRow {
  std::string method;
  int iterations = 0;
  SmoothOptions options;
  double ms = 0, volume_change = 0, voxel_volume_change = 0;
  Deviation deviation;
  QualityStats quality;
  QualityStats voxel_quality;  // in voxel units
};

std::string smoothing_label(const SmoothOptions& o, bool with_iterations = true) {
  std::string s(smooth_method_name(o.method));
  if (o.method == SmoothMethod::none) return s;
  if (o.preserve_volume) s = "segmesh default: " + s;
  if (with_iterations) {
    s += " x" + std::to_string(o.iterations);
  }
  if (o.method == SmoothMethod::sinc) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " (pass band %g%s)", o.pass_band,
                  o.sinc_unit_gain ? ", unit gain" : ", as 3D Slicer");
    s += buf;
  }
  return s;
}

// A picture's size for the scene in the iso view: the longer side 720 pixels, the aspect of the
// scene's outline (between 1:2 and 2:1), so a long bone is not a sliver in a landscape frame.
std::pair<int, int> picture_size(const Scene& scene) {
  render::Camera camera = render::standard_camera(scene, render::StandardView::iso, 1.0);
  const render::Bounds b = render::scene_bounds(scene);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (int i = 0; i < 8; ++i) {
    const Vec3d p{i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z};
    if (const auto px = render::project_to_pixel(camera, 1000, 1000, p)) {
      x0 = std::min(x0, px->x), x1 = std::max(x1, px->x);
      y0 = std::min(y0, px->y), y1 = std::max(y1, px->y);
    }
  }
  const double aspect = x1 > x0 && y1 > y0 ? std::clamp((x1 - x0) / (y1 - y0), 0.5, 2.0) : 4.0 / 3;
  return aspect >= 1 ? std::pair{720, int(720 / aspect)} : std::pair{int(720 * aspect), 720};
}

struct Picture {
  std::string file, caption;
};

// Renders the study's scenes (iso view, ambient occlusion, anti-aliased) into DIR. Without an
// OpenGL context (no EGL, no Mesa) the study goes on without pictures and says so.
std::vector<Picture> render_pictures(const fs::path& dir,
                                     const std::vector<std::pair<const Scene*, Picture>>& scenes,
                                     bool quiet) {
  std::vector<Picture> done;
  std::unique_ptr<render::HeadlessContext> context;
  try {
    context = std::make_unique<render::HeadlessContext>();
  } catch (const Error& e) {
    std::fprintf(stderr, "segmesh: warning: study without pictures: %s\n", e.what());
    return done;
  }
  render::Renderer renderer;
  for (const auto& [scene, picture] : scenes) {
    const auto [w, h] = picture_size(*scene);
    render::RenderOptions options;
    options.supersample = 2;
    options.color = picture.file.find("quality") != std::string::npos ? render::ColorMode::quality
                                                                       : render::ColorMode::material;
    const render::Camera camera =
        render::standard_camera(*scene, render::StandardView::iso, double(w) / h);
    render::write_png(renderer.render_image(*scene, camera, options, w, h), dir / picture.file);
    done.push_back(picture);
  }
  if (!quiet && !done.empty()) {
    std::printf("rendered %zu pictures (%s)\n", done.size(), context->description().c_str());
  }
  return done;
}

int run_study(const StudyArgs& args) {
  const fs::path dir = args.output;
  if (!fs::exists(dir)) require_parent_folder(dir);
  MeshingOptions base;
  base.labels = args.labels;
  base.iso = args.iso;
  base.smooth = {};  // extraction first; each smoothing is studied on its own
  if (!args.label_names.empty()) base.label_names = read_label_names(args.label_names);
  // A bad request stops before the volume is read. The request itself goes on: each method
  // resolves its own surfaces (conforming for Marching Cubes, independent for Dual Contouring).
  resolve_meshing_options(base);
  const auto threads = limit_threads(args.threads);
  const Image image = read_input(args.input, args.read);
  ProgressBar progress(!args.quiet);

  // Table 1.
  std::vector<Extraction> extractions;
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    MeshingOptions o = base;
    o.method = method;
    PipelineStats stats;
    Extraction e;
    e.name = method == Method::dual_contouring ? "Dual Contouring" : "Marching Cubes";
    e.scene = build_scene(image, o, progress, &stats);
    e.ms = stats.components_ms + stats.extract_ms;
    e.all = merged(e.scene);
    extractions.push_back(std::move(e));
  }
  double voxel_volume = 0;
  for (const Part& p : extractions[0].scene.parts) voxel_volume += p.voxel_volume_mm3;

  // Table 2 (on Marching Cubes, as the reference) and Table 3 (both extractions).
  std::vector<SmoothOptions> settings;
  // The plain filters, as the reference ran them (no volume restoration); windowed sinc as
  // 3D Slicer runs it (VTK's coefficients, without unit gain); then segmesh's default.
  auto add = [&](SmoothMethod m, int iterations) {
    SmoothOptions o;
    o.method = m;
    o.iterations = iterations;
    o.preserve_volume = false;
    o.sinc_unit_gain = false;
    settings.push_back(o);
  };
  for (int n : {2, 4, 5}) add(SmoothMethod::laplacian, n);
  for (int n : {2, 4, 5}) add(SmoothMethod::hc, n);
  for (int n : {10, 20, 40}) add(SmoothMethod::taubin, n);
  add(SmoothMethod::sinc, 20);  // 3D Slicer's default: pass band 0.01, 20 iterations
  const SmoothOptions ours = resolve_meshing_options({}).smooth;  // segmesh mesh's default
  if (ours.method != SmoothMethod::none) settings.push_back(ours);

  std::vector<std::vector<SmoothRow>> rows(extractions.size());
  for (size_t e = 0; e < extractions.size(); ++e) {
    const double before = scene_volume(extractions[e].scene);
    for (const SmoothOptions& s : settings) {
      // Table 3 needs HC, Taubin and sinc on Dual Contouring too; Table 2 only on MC.
      if (e > 0 && s.method == SmoothMethod::laplacian) continue;
      Scene smoothed = extractions[e].scene;
      const auto start = std::chrono::steady_clock::now();
      smooth_scene(smoothed, s, progress);
      SmoothRow row;
      row.method = std::string(smooth_method_name(s.method));
      row.iterations = s.iterations;
      row.options = s;
      row.ms = ms_since(start);
      const double after = scene_volume(smoothed);
      row.volume_change = 100 * (after - before) / before;
      row.voxel_volume_change = 100 * (after - voxel_volume) / voxel_volume;
      const TriMesh all = merged(smoothed);
      row.deviation = mesh_deviation(extractions[e].all, all);
      row.quality = triangle_quality(all);
      row.voxel_quality = triangle_quality(in_voxel_units(all, image.grid()));
      rows[e].push_back(row);
    }
  }
  progress.finish();

  // Colour-coded meshes: both extractions, unsmoothed and with the default smoothing.
  fs::create_directories(dir);
  std::vector<std::string> written;
  auto write_colored = [&](Scene scene, const std::string& name) {
    color_scene_by_quality(scene);
    write_scene(scene, dir / name, MeshFormat::glb);
    written.push_back(name);
  };
  std::vector<Scene> smoothed_scenes;  // with segmesh's default smoothing, per extraction
  for (size_t e = 0; e < extractions.size(); ++e) {
    const std::string tag = e == 0 ? "mc" : "dc";
    write_colored(extractions[e].scene, tag + "_quality.glb");
    if (ours.method != SmoothMethod::none) {
      Scene smoothed = extractions[e].scene;
      smooth_scene(smoothed, ours);
      write_colored(smoothed, tag + "_" + std::string(smooth_method_name(ours.method)) +
                                  "_quality.glb");
      smoothed_scenes.push_back(std::move(smoothed));
    }
  }

  // Pictures: both extractions as extracted, Marching Cubes smoothed, and the triangle quality.
  std::vector<std::pair<const Scene*, Picture>> to_render = {
      {&extractions[0].scene, {"mc.png", "Marching Cubes"}},
      {&extractions[1].scene, {"dc.png", "Dual Contouring"}},
  };
  const std::string smooth_name(smooth_method_name(ours.method));
  if (!smoothed_scenes.empty()) {
    to_render.push_back({&smoothed_scenes[0], {"mc_" + smooth_name + ".png",
                                                "Marching Cubes, smoothed (" + smoothing_label(ours) + ")"}});
  }
  to_render.push_back({&extractions[0].scene, {"mc_quality.png", "Marching Cubes, radii ratio"}});
  to_render.push_back({&extractions[1].scene, {"dc_quality.png", "Dual Contouring, radii ratio"}});
  if (!smoothed_scenes.empty()) {
    to_render.push_back({&smoothed_scenes[0], {"mc_" + smooth_name + "_quality.png",
                                                "Marching Cubes, smoothed, radii ratio"}});
  }
  const std::vector<Picture> pictures = render_pictures(dir, to_render, args.quiet);

  // study.json
  nlohmann::json j;
  j["input"] = grid_json(image.grid());
  j["input"]["path"] = image.path;
  j["voxel_volume_mm3"] = voxel_volume;
  for (size_t e = 0; e < extractions.size(); ++e) {
    const Extraction& x = extractions[e];
    const QualityStats q = triangle_quality(x.all);
    nlohmann::json ej = {{"method", e == 0 ? "mc" : "dc"},
                         {"parts", x.scene.parts.size()},
                         {"vertices", x.all.positions.size()},
                         {"triangles", x.all.triangle_count()},
                         {"time_ms", x.ms},
                         {"volume_mm3", scene_volume(x.scene)},
                         {"radii_ratio", {{"min", q.min}, {"mean", q.mean}, {"p01", q.p01}}}};
    const QualityStats qv = triangle_quality(in_voxel_units(x.all, image.grid()));
    ej["radii_ratio_voxel_units"] = {{"min", qv.min}, {"mean", qv.mean}};
    for (const SmoothRow& r : rows[e]) {
      ej["smoothing"].push_back({{"method", r.method},
                                 {"iterations", r.iterations},
                                 {"pass_band", r.options.pass_band},
                                 {"sinc_unit_gain", r.options.sinc_unit_gain},
                                 {"preserve_volume", r.options.preserve_volume},
                                 {"time_ms", r.ms},
                                 {"volume_change_percent", r.volume_change},
                                 {"volume_vs_voxels_percent", r.voxel_volume_change},
                                 {"deviation_mm",
                                  {{"hausdorff", r.deviation.hausdorff},
                                   {"mean", r.deviation.mean},
                                   {"p95", r.deviation.p95}}},
                                 {"radii_ratio", {{"min", r.quality.min}, {"mean", r.quality.mean}}},
                                 {"radii_ratio_voxel_units",
                                  {{"min", r.voxel_quality.min}, {"mean", r.voxel_quality.mean}}}});
    }
    j["extractions"].push_back(ej);
  }
  j["meshes"] = written;
  j["pictures"] = nlohmann::json::array();
  for (const Picture& p : pictures) j["pictures"].push_back({{"file", p.file}, {"caption", p.caption}});

  // study.md
  std::ostringstream md;
  char line[512];
  const Grid& g = image.grid();
  md << "# segmesh study: " << fs::path(image.path).filename().string() << "\n\n";
  std::snprintf(line, sizeof line,
                "%lld x %lld x %lld voxels at %g x %g x %g mm, %zu parts, voxel volume %.1f mm3. "
                "Written by `segmesh study`.\n\n",
                (long long)g.dims[0], (long long)g.dims[1], (long long)g.dims[2], g.spacing[0],
                g.spacing[1], g.spacing[2], extractions[0].scene.parts.size(), voxel_volume);
  md << line;
  md << "## Table 1: extraction\n\n| method | vertices | triangles | time (ms) |\n| --- | ---: | ---: | ---: |\n";
  for (const Extraction& x : extractions) {
    std::snprintf(line, sizeof line, "| %s | %zu | %zu | %.0f |\n", x.name.c_str(),
                  x.all.positions.size(), x.all.triangle_count(), x.ms);
    md << line;
  }
  md << "\nReference thesis (512x512x203 CT): Marching Cubes 1,280,594 vertices, 2,561,094 triangles, "
        "4 s; Dual Contouring 1,328,392 vertices, 2,672,612 triangles, 10 s.\n\n";
  md << "## Table 2: smoothing of the Marching Cubes mesh\n\n"
        "| method | iterations | volume change | vs voxel volume | deviation mean / p95 / Hausdorff (mm) | time (ms) |\n"
        "| --- | ---: | ---: | ---: | --- | ---: |\n";
  for (const SmoothRow& r : rows[0]) {
    std::snprintf(line, sizeof line, "| %s | %d | %+.3f %% | %+.3f %% | %.4f / %.4f / %.4f | %.0f |\n",
                  smoothing_label(r.options, false).c_str(), r.iterations, r.volume_change,
                  r.voxel_volume_change, r.deviation.mean, r.deviation.p95, r.deviation.hausdorff, r.ms);
    md << line;
  }
  md << "\nReference thesis (volume decrease, time): Laplacian 2/4/5: 42.46 / 51.78 / 54.63 %, "
        "1.5 / 3 / 4.8 s; HC 2/4/5: 12.65 / 16.6 / 17.08 %, 1.8 / 3.7 / 5.2 s; Taubin 10/20/40: "
        "8.13 / 22.3 / 37.47 %, 8.5 / 12 / 17 s.\n\n";
  md << "## Table 3: triangle quality (radii ratio 2r/R)\n\nIn millimetres, and in voxel units (the "
        "mesh with the spacing undone: how well the triangles fit the grid, whatever its "
        "anisotropy).\n\n| mesh | min | mean | min (voxel units) | mean (voxel units) |\n"
        "| --- | ---: | ---: | ---: | ---: |\n";
  for (size_t e = 0; e < extractions.size(); ++e) {
    const std::string tag = e == 0 ? "MC" : "DC";
    const QualityStats q = triangle_quality(extractions[e].all);
    const QualityStats qv = triangle_quality(in_voxel_units(extractions[e].all, image.grid()));
    std::snprintf(line, sizeof line, "| %s | %.5f | %.5f | %.5f | %.5f |\n", tag.c_str(), q.min,
                  q.mean, qv.min, qv.mean);
    md << line;
    for (const SmoothRow& r : rows[e]) {
      const bool shown = (r.options.method == SmoothMethod::hc && r.iterations == 2) ||
                         (r.options.method == SmoothMethod::taubin && r.iterations == 20) ||
                         r.options.method == SmoothMethod::sinc || r.options.preserve_volume;
      if (!shown) continue;
      std::snprintf(line, sizeof line, "| %s with %s | %.5f | %.5f | %.5f | %.5f |\n", tag.c_str(),
                    smoothing_label(r.options).c_str(), r.quality.min, r.quality.mean,
                    r.voxel_quality.min, r.voxel_quality.mean);
      md << line;
    }
  }
  md << "\nReference thesis: MC 0.00674 / 0.55589; MC with HC 0.00706 / 0.59855; MC with Taubin "
        "0.007014 / 0.57105; DC 0.008768 / 0.76992; DC with HC 0.007768 / 0.69817; DC with Taubin "
        "0.007662 / 0.68719.\n\nColour-coded meshes (blue: radii ratio 0, green: 1):";
  for (const std::string& w : written) md << " `" << w << "`";
  md << "\n";
  if (!pictures.empty()) {
    md << "\n## Pictures\n\nIso view (anterior, left, above), ambient occlusion on; radii ratio from blue "
          "(0) to green (1).\n\n";
    for (const Picture& p : pictures) md << p.caption << ":\n\n![" << p.caption << "](" << p.file << ")\n\n";
  }

  AtomicFile json_file(dir / "study.json");
  json_file.stream() << j.dump(2) << '\n';
  json_file.commit();
  AtomicFile md_file(dir / "study.md");
  md_file.stream() << md.str();
  md_file.commit();
  if (!args.quiet) {
    std::printf("%s", md.str().c_str());
    std::printf("\nwrote %s/study.md, study.json, %zu meshes and %zu pictures\n", dir.string().c_str(),
                written.size(), pictures.size());
  }
  return 0;
}

}  // namespace

Subcommand add_study_command(CLI::App& app) {
  auto a = std::make_shared<StudyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "study", "Reproduce the reference thesis's evaluation (Tables 1-3) on a volume");
  cmd->add_option("input", a->input, "volume file or DICOM folder")->required();
  cmd->add_option("-o,--output", a->output, "folder for study.md, study.json, meshes and pictures")->required();
  cmd->add_option("--labels", a->labels, "labels to study (default: every non-zero label)")->delimiter(',');
  cmd->add_option("--iso", a->iso, "study a grey-value volume at this iso value");
  cmd->add_option("--label-names", a->label_names, "TSV file: label, name[, role]");
  cmd->add_option("--threads", a->threads, "worker threads (0: all cores)")->capture_default_str();
  add_read_options(cmd, a->read);
  cmd->add_flag("--quiet", a->quiet, "print nothing");
  return {cmd, [a] { return run_study(*a); }};
}

}  // namespace segmesh::cli
