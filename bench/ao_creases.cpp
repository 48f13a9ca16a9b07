// Ambient occlusion on the crease scene of issue 40 (tests/segmesh_render/crease_scene.hpp: a
// bone block, a fragment resting on it, a screw entering it): the same camera rendered with
// occlusion on and off, as `segmesh render` does (iso view, supersample 2) and as the viewer does
// (supersample 1). Prints, per size, how much darker the object pixels get (99th percentile and
// mean, luminance of 255), how much the block's flat open top changes, and the render times.
//
//   build/bench/segmesh_ao_creases [OUT_DIR [RADIUS_MM]]
// OUT_DIR (or ""): also write the on/off pictures there; RADIUS_MM: RenderOptions::ao_radius_mm
// (default 0, the renderer's own choice).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "segmesh_render/crease_scene.hpp"
#include "segmesh_render/headless_context.hpp"
#include "segmesh_render/png.hpp"

using namespace segmesh;

namespace {

// The median time of `runs` renders, ms, and the last picture.
render::RgbaImage timed(render::Renderer& r, const Scene& s, const render::Camera& c,
                        const render::RenderOptions& o, int w, int h, double& ms) {
  std::vector<double> times;
  render::RgbaImage img;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    img = r.render_image(s, c, o, w, h);
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(times.begin(), times.end());
  ms = times[times.size() / 2];
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : "";
  const double radius_mm = argc > 2 ? std::atof(argv[2]) : 0;
  const Scene scene = test::crease_scene();
  render::HeadlessContext context;
  render::Renderer renderer;
  const render::AoParameters ao =
      render::ao_parameters({.ao_radius_mm = radius_mm}, render::scene_bounds(scene).diagonal());
  std::printf("%zu parts; %s; occlusion radius %.2f mm, bias %.3f mm\n", scene.parts.size(),
              context.description().c_str(), ao.radius_mm, ao.bias_mm);
  std::printf("%-10s %4s %9s %9s %9s %9s %9s %9s\n", "size", "ss", "p99 dark", "mean dark",
              "open p99", "open mean", "ms on", "ms off");
  struct Case { int w, h, ss; };
  for (const Case c : {Case{1024, 768, 2}, Case{1024, 768, 1}, Case{400, 300, 2}}) {
    const render::Camera camera = test::crease_camera(scene, c.w, c.h);
    render::RenderOptions on, off;
    on.supersample = off.supersample = c.ss;
    off.ambient_occlusion = false;
    on.ao_radius_mm = radius_mm;
    double ms_on = 0, ms_off = 0;
    const render::RgbaImage with = timed(renderer, scene, camera, on, c.w, c.h, ms_on);
    const render::RgbaImage without = timed(renderer, scene, camera, off, c.w, c.h, ms_off);
    const std::vector<int32_t> ids = renderer.render_ids(scene, camera, on, c.w, c.h);
    const std::vector<double> d = test::darkening(with, without, test::object_pixels(ids));
    // The open top: farther than the occlusion radius (and 1 mm more) from anything that rises.
    std::vector<double> open =
        test::darkening(with, without, test::open_top_pixels(ids, camera, c.w, c.h, 0, ao.radius_mm + 1));
    for (double& x : open) x = std::abs(x);
    double mean = 0, open_mean = 0;
    for (double x : d) mean += x / double(d.size());
    for (double x : open) open_mean += x / double(open.size());
    std::printf("%4dx%-5d %4d %9.1f %9.2f %9.2f %9.2f %9.0f %9.0f   (%zu object, %zu open pixels)\n",
                c.w, c.h, c.ss, test::quantile(d, 0.99), mean, test::quantile(open, 0.99), open_mean,
                ms_on, ms_off, d.size(), open.size());
    if (!out.empty()) {
      const std::string tag = std::to_string(c.w) + "x" + std::to_string(c.h) + "_ss" + std::to_string(c.ss);
      render::write_png(with, out / ("creases_ao_on_" + tag + ".png"));
      render::write_png(without, out / ("creases_ao_off_" + tag + ".png"));
    }
  }
  return 0;
}
