// segmesh render INPUT -o view.png [options]: a picture of the meshes without a display. INPUT is
// a volume, meshed by the pipeline with the same options as `segmesh mesh`, or a mesh or scene
// file (GLB, PLY, STL, OBJ). The picture is drawn by segmesh_render in an OpenGL context made
// through EGL (Mesa's llvmpipe when there is no GPU) and written as PNG. Every check that can fail
// on the user's request runs before the meshing starts, but for part names (--hide, --fit), which
// need the scene; a machine without OpenGL is found out before the meshing too.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "meshing_args.hpp"
#include "progress_bar.hpp"
#include "segmesh/error.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/headless_context.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct RenderArgs {
  std::string input;
  std::string output;
  MeshingArgs meshing;
  std::string view = "iso";
  std::string size = "1024,768";
  std::string color = "material";
  std::string ao = "on";
  double ao_radius = 0;
  std::vector<std::string> hide;
  std::vector<std::string> fit;
  std::string clip;
  int supersample = 2;
  double zoom = 1;
  int threads = 0;
  bool quiet = false;
  ReadArgs read;
};

// "W,H" with both in 1..16384.
std::pair<int, int> parse_size(const std::string& text) {
  std::istringstream in(text);
  long w = 0, h = 0;
  char comma = 0;
  if (!(in >> w >> comma >> h) || comma != ',' || in.peek() != std::char_traits<char>::eof() ||
      w < 1 || h < 1 || w > 16384 || h > 16384) {
    throw Error("--size expects the width and height in pixels like 1024,768 (each 1 to 16384; got \"" +
                text + "\")");
  }
  return {int(w), int(h)};
}

// "X,Y,Z,NX,NY,NZ": a point on the plane and the normal of the side that is kept.
render::ClipPlane parse_clip(const std::string& text) {
  std::istringstream in(text);
  double v[6];
  for (int i = 0; i < 6; ++i) {
    if (!(in >> v[i]) || (i < 5 && in.get() != ',')) {
      throw Error("--clip expects six comma-separated numbers X,Y,Z,NX,NY,NZ (a point in mm and the "
                  "normal of the half that stays; got \"" + text + "\")");
    }
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    throw Error("--clip expects exactly six numbers (got \"" + text + "\")");
  }
  render::ClipPlane plane{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  if (norm(plane.normal) == 0) throw Error("--clip: the normal (NX,NY,NZ) must not be zero");
  return plane;
}

// The parts `names` select: a part's name, or a role (bone, implant, other) for every part with
// that role. Throws segmesh::Error naming `option` for a name that selects nothing.
std::vector<bool> select_parts(const Scene& scene, const std::vector<std::string>& names,
                               const std::string& option) {
  std::vector<bool> selected(scene.parts.size(), false);
  for (const std::string& name : names) {
    bool found = false;
    for (size_t i = 0; i < scene.parts.size(); ++i) {
      const Part& p = scene.parts[i];
      if (p.name == name || role_name(p.role) == name) selected[i] = found = true;
    }
    if (!found) {
      std::string list;
      for (size_t i = 0; i < scene.parts.size() && i < 12; ++i) {
        list += (i ? ", " : "") + scene.parts[i].name;
      }
      if (scene.parts.size() > 12) list += ", ...";
      throw Error(option + ": no part named \"" + name + "\" (the parts: " + list +
                  "; or a role: bone, implant, other)");
    }
  }
  return selected;
}

int run_render(const RenderArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  // Every check on the request first.
  const fs::path output = args.output;
  std::string ext = output.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".png") throw Error(args.output + ": the picture is written as PNG; name it *.png");
  require_parent_folder(output);
  refuse_to_overwrite(output, args.input);
  const auto view = render::parse_view(args.view);
  if (!view) {
    throw Error("--view must be anterior, posterior, left, right, superior, inferior or iso (got \"" +
                args.view + "\")");
  }
  const auto color = render::parse_color_mode(args.color);
  if (!color) throw Error("--color must be material or quality (got \"" + args.color + "\")");
  if (args.ao != "on" && args.ao != "off") throw Error("--ao must be on or off (got \"" + args.ao + "\")");
  if (!(args.ao_radius >= 0) || !std::isfinite(args.ao_radius)) {
    throw Error("--ao-radius must be 0 (automatic) or a positive number of mm");
  }
  if (args.supersample < 1 || args.supersample > 4) throw Error("--supersample must be 1 to 4");
  if (!(args.zoom > 0) || !std::isfinite(args.zoom)) throw Error("--zoom must be a positive number");
  const auto [width, height] = parse_size(args.size);
  render::RenderOptions options;
  options.color = *color;
  options.ambient_occlusion = args.ao == "on";
  options.ao_radius_mm = args.ao_radius;
  options.supersample = args.supersample;
  if (!args.clip.empty()) options.clip = parse_clip(args.clip);
  const bool mesh_input = mesh_format_from_path(args.input).has_value();
  const MeshingOptions meshing = mesh_input ? MeshingOptions{} : meshing_options(args.meshing);
  const auto threads = limit_threads(args.threads);
  // A missing OpenGL stops the command before the meshing, not after.
  render::HeadlessContext context;

  auto step = std::chrono::steady_clock::now();
  Scene scene;
  if (mesh_input) {
    scene = read_mesh(args.input);
  } else {
    const Image image = read_input(args.input, args.read);
    ProgressBar progress(!args.quiet);
    scene = build_scene(image, meshing, progress);
    progress.finish();
  }
  const double mesh_ms = ms_since(step);
  const std::vector<bool> hide = select_parts(scene, args.hide, "--hide");
  int hidden = 0;
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    if (hide[i] && scene.parts[i].visible) ++hidden;
    if (hide[i]) scene.parts[i].visible = false;
  }
  // The camera frames the visible parts, or those --fit names.
  Scene framed = scene;
  if (!args.fit.empty()) {
    const std::vector<bool> fit = select_parts(scene, args.fit, "--fit");
    for (size_t i = 0; i < framed.parts.size(); ++i) framed.parts[i].visible = fit[i];
  }

  step = std::chrono::steady_clock::now();
  render::Renderer renderer;
  render::Camera camera = render::standard_camera(framed, *view, double(width) / height);
  render::zoom(camera, args.zoom);
  const render::RgbaImage image = renderer.render_image(scene, camera, options, width, height);
  const double render_ms = ms_since(step);
  render::write_png(image, output);
  if (!args.quiet) {
    std::printf("%zu parts (%d hidden), %lld triangles drawn; %s in %.0f ms, rendered in %.0f ms "
                "(%s)\n",
                scene.parts.size(), hidden, (long long)renderer.last_frame().triangles_drawn,
                mesh_input ? "read" : "meshed", mesh_ms, render_ms, context.description().c_str());
    std::printf("wrote %s (%d x %d, %s view, %s colours, ambient occlusion %s) in %.0f ms\n",
                args.output.c_str(), width, height, args.view.c_str(), args.color.c_str(),
                args.ao.c_str(), ms_since(start));
  }
  return 0;
}

}  // namespace

Subcommand add_render_command(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a volume's meshes, or a mesh or scene file, to a PNG picture (no display needed)");
  cmd->add_option("input", a->input,
                  "volume file or DICOM folder (meshed as by segmesh mesh), or a mesh or scene "
                  "(.glb, .ply, .stl, .obj)")
      ->required();
  cmd->add_option("-o,--output", a->output, "the picture, a .png file")->required();
  cmd->add_option("--view", a->view, "anterior, posterior, left, right, superior, inferior or iso")
      ->capture_default_str();
  cmd->add_option("--size", a->size, "width,height in pixels")->capture_default_str();
  cmd->add_option("--color", a->color,
                  "material (bone white, implant metallic red) or quality (radii ratio, blue 0 to green 1)")
      ->capture_default_str();
  cmd->add_option("--ao", a->ao, "screen-space ambient occlusion: on or off")->capture_default_str();
  cmd->add_option("--ao-radius", a->ao_radius,
                  "how far occluders reach, mm (0: 6 % of the visible parts' diagonal, 2 to 10 mm)")
      ->capture_default_str();
  cmd->add_option("--hide", a->hide, "parts to leave out, by name or role (bone, implant, other)")
      ->delimiter(',');
  cmd->add_option("--clip", a->clip,
                  "cut with a plane X,Y,Z,NX,NY,NZ (mm): the half the normal points into stays");
  cmd->add_option("--fit", a->fit,
                  "frame these parts, by name or role, instead of every visible part")
      ->delimiter(',');
  cmd->add_option("--zoom", a->zoom,
                  "magnification about the centre of the framed parts (1: they just fit; < 1: farther)")
      ->capture_default_str();
  cmd->add_option("--supersample", a->supersample,
                  "anti-aliasing: render N x N samples per pixel (1 to 4)")
      ->capture_default_str();
  add_meshing_options(cmd, a->meshing);
  add_read_options(cmd, a->read);
  cmd->add_option("--threads", a->threads, "worker threads for the meshing (0: all cores)")
      ->capture_default_str();
  cmd->add_flag("--quiet", a->quiet, "no progress bar and no summary");
  return {cmd, [a] { return run_render(*a); }};
}

}  // namespace segmesh::cli
