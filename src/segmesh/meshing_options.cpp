#include "segmesh/meshing_options.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "segmesh/error.hpp"

namespace segmesh {

std::string_view method_name(Method method) {
  return method == Method::dual_contouring ? "dc" : "mc";
}

std::optional<Method> parse_method(std::string_view name) {
  if (name == "mc") return Method::marching_cubes;
  if (name == "dc") return Method::dual_contouring;
  return std::nullopt;
}

std::string_view surfaces_name(Surfaces surfaces) {
  switch (surfaces) {
    case Surfaces::conforming:
      return "conforming";
    case Surfaces::independent:
      return "independent";
    case Surfaces::automatic:
      break;
  }
  return "automatic";
}

std::optional<Surfaces> parse_surfaces(std::string_view name) {
  if (name == "independent") return Surfaces::independent;
  if (name == "conforming") return Surfaces::conforming;
  if (name == "automatic") return Surfaces::automatic;
  return std::nullopt;
}

std::string_view normals_name(NormalMethod normals) {
  return normals == NormalMethod::sobel ? "sobel" : "central";
}

std::optional<NormalMethod> parse_normals(std::string_view name) {
  if (name == "central") return NormalMethod::central;
  if (name == "sobel") return NormalMethod::sobel;
  return std::nullopt;
}

SmoothOptions default_smoothing() {
  SmoothOptions o;  // the pass band and the restored volume as SmoothOptions has them
  o.method = SmoothMethod::sinc;
  o.iterations = 0;
  o.sinc_unit_gain = true;
  return o;
}

namespace {

// The shortest text that reads back as the same double ("0.5", "1e-06").
std::string number_text(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, ec == std::errc() ? end : buf);
}

std::string got(double v) {
  return " (got " + number_text(v) + ")";
}


// What keeps a request from conforming surfaces, if anything: the one rule behind the automatic
// choice, the refusal of --surfaces conforming and surfaces_note.
enum class ConformingObstacle { none, dc_tolerance, iso, presmooth };

ConformingObstacle conforming_obstacle(const MeshingOptions& o) {
  if (o.iso) return ConformingObstacle::iso;
  if (o.volume_sigma_mm > 0) return ConformingObstacle::presmooth;
  if (o.method == Method::dual_contouring && o.dc_tolerance_mm > 0)
    return ConformingObstacle::dc_tolerance;
  return ConformingObstacle::none;
}

}  // namespace

std::optional<std::string> surfaces_note(const MeshingOptions& o) {
  // Grey values are no label map: nothing to say.
  if (o.surfaces != Surfaces::automatic || o.iso) return std::nullopt;
  switch (conforming_obstacle(o)) {
    case ConformingObstacle::dc_tolerance:
      return "--dc-tolerance simplifies every part's own surface: where parts touch, each has its "
             "own surface (decimate instead for shared contacts)";
    case ConformingObstacle::presmooth:
      return "--presmooth smooths every part's own field: where parts touch, each has its own "
             "surface (smooth the mesh instead for shared contacts)";
    case ConformingObstacle::iso:
    case ConformingObstacle::none:
      break;
  }
  return std::nullopt;
}

MeshingOptions resolve_meshing_options(MeshingOptions o) {
  auto fail = [](const std::string& message) { throw Error(message); };
  for (int32_t label : o.labels) {
    if (label == 0) fail("--labels: 0 is the background and has no surface");
  }
  if (o.iso && !o.labels.empty()) {
    fail("--labels and --iso exclude each other: --iso meshes a grey-value volume");
  }
  if (o.iso && !std::isfinite(*o.iso)) fail("--iso must be a finite number");
  if (!is_connectivity(o.connectivity)) {
    fail("--connectivity must be 6, 18 or 26 (got " + std::to_string(o.connectivity) + ")");
  }
  if (o.min_voxels < 0) fail("--min-voxels must not be negative" + got(double(o.min_voxels)));
  if (!(o.volume_sigma_mm >= 0) || !std::isfinite(o.volume_sigma_mm)) {
    fail("--presmooth must be a non-negative number of millimetres" + got(o.volume_sigma_mm));
  }
  if (!(o.dc_svd_eps >= 0 && o.dc_svd_eps <= 1))
    fail("--dc-svd-eps must be between 0 and 1" + got(o.dc_svd_eps));
  if (!(o.dc_tolerance_mm >= 0) || !std::isfinite(o.dc_tolerance_mm)) {
    fail("--dc-tolerance must be a non-negative number of millimetres" + got(o.dc_tolerance_mm));
  }
  const ConformingObstacle obstacle = conforming_obstacle(o);
  if (o.surfaces == Surfaces::automatic) {
    o.surfaces = obstacle == ConformingObstacle::none ? Surfaces::conforming : Surfaces::independent;
  } else if (o.surfaces == Surfaces::conforming) {
    switch (obstacle) {
      case ConformingObstacle::dc_tolerance:
        fail("--dc-tolerance simplifies each part's own surface; with --surfaces conforming "
             "decimate instead (--decimate-error), or add --surfaces independent");
        break;
      case ConformingObstacle::iso:
        fail("--surfaces conforming meshes label maps; with --iso use --surfaces independent");
        break;
      case ConformingObstacle::presmooth:
        fail("--presmooth smooths each part's own field; with --surfaces conforming smooth the "
             "mesh instead (--smooth), or add --surfaces independent");
        break;
      case ConformingObstacle::none:
        break;
    }
  }
  SmoothOptions& s = o.smooth;
  if (const auto problem = smooth_options_problem(s)) {
    std::string option(problem->option);
    std::replace(option.begin(), option.end(), '_', '-');  // taubin_mu: --taubin-mu
    fail("--" + option + " " + problem->rule);
  }
  if (s.iterations == 0) s.iterations = default_smooth_iterations(s.method);
  if (const auto problem = decimate_options_problem(o.decimate)) {
    const double value = problem->option == "decimate-error" ? o.decimate.error_mm
                         : problem->option == "max-triangles"
                             ? double(o.decimate.max_triangles)
                             : double(o.decimate.max_triangles_per_part);
    fail("--" + std::string(problem->option) + " " + std::string(problem->rule) + got(value));
  }
  return o;
}

namespace {

// ---- text to values, with the option's name in every message --------------------------------

[[noreturn]] void bad_value(std::string_view option, std::string_view expected,
                            std::string_view text) {
  throw Error("--" + std::string(option) + " expects " + std::string(expected) + " (got \"" +
              std::string(text) + "\")");
}

template <class Int>
Int whole_number(std::string_view option, std::string_view text) {
  Int value{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) {
    bad_value(option, "a whole number", text);
  }
  return value;
}

double number(std::string_view option, std::string_view text) {
  // from_chars takes no leading '+'; a user may write one.
  std::string_view digits = text.starts_with('+') ? text.substr(1) : text;
  double value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty()) {
    bad_value(option, "a number", text);
  }
  return value;
}

bool flag(std::string_view option, std::string_view text) {
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  bad_value(option, "true or false", text);
}

std::vector<int32_t> label_list(std::string_view text) {
  std::vector<int32_t> labels;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string_view item = text.substr(start, comma - start);
    if (!item.empty()) {
      int32_t value = 0;
      const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
      if (ec != std::errc() || end != item.data() + item.size()) {
        bad_value("labels", "whole numbers like 1,2", text);
      }
      labels.push_back(value);
    }
    start = comma + 1;
  }
  return labels;
}

std::string labels_text(const std::vector<int32_t>& labels) {
  std::string s;
  for (int32_t l : labels) s += (s.empty() ? "" : ",") + std::to_string(l);
  return s;
}

// ---- the table -------------------------------------------------------------------------------

// Spec members are plain function pointers; the lambdas below capture nothing.
using O = MeshingOptions;

constexpr std::array kSpecs = {
    MeshingOptionSpec{"method", "TEXT", "extraction: mc (Marching Cubes) or dc (Dual Contouring)",
                      [](const O& o) { return std::string(method_name(o.method)); },
                      [](O& o, std::string_view t) {
                        const auto m = parse_method(t);
                        if (!m)
                          throw Error("--method must be mc or dc (got \"" + std::string(t) + "\")");
                        o.method = *m;
                      }},
    MeshingOptionSpec{"surfaces", "TEXT",
                      "conforming (contacts between parts meshed and smoothed once; the default "
                      "for label maps with Marching Cubes) or independent (each part on its own)",
                      [](const O& o) { return std::string(surfaces_name(o.surfaces)); },
                      [](O& o, std::string_view t) {
                        const auto s = parse_surfaces(t);
                        if (!s) {
                          throw Error(
                              "--surfaces must be conforming, independent or automatic (got \"" +
                              std::string(t) + "\")");
                        }
                        o.surfaces = *s;
                      }},
    MeshingOptionSpec{"labels", "INT LIST",
                      "labels to mesh, e.g. 1,2 (default: every non-zero label)",
                      [](const O& o) { return labels_text(o.labels); },
                      [](O& o, std::string_view t) { o.labels = label_list(t); }},
    MeshingOptionSpec{"iso", "FLOAT", "mesh a grey-value volume (e.g. CT in HU) at this value",
                      [](const O& o) { return o.iso ? number_text(*o.iso) : std::string(); },
                      [](O& o, std::string_view t) {
                        if (t.empty()) {
                          o.iso.reset();
                        } else {
                          o.iso = number("iso", t);
                        }
                      }},
    MeshingOptionSpec{
        "connectivity", "INT", "voxel connectivity of parts: 6, 18 or 26",
        [](const O& o) { return std::to_string(o.connectivity); },
        [](O& o, std::string_view t) { o.connectivity = whole_number<int>("connectivity", t); }},
    MeshingOptionSpec{
        "min-voxels", "INT", "drop components with fewer voxels",
        [](const O& o) { return std::to_string(o.min_voxels); },
        [](O& o, std::string_view t) { o.min_voxels = whole_number<int64_t>("min-voxels", t); }},
    MeshingOptionSpec{"normals", "TEXT", "vertex normals: central or sobel",
                      [](const O& o) { return std::string(normals_name(o.normals)); },
                      [](O& o, std::string_view t) {
                        const auto n = parse_normals(t);
                        if (!n)
                          throw Error("--normals must be central or sobel (got \"" +
                                      std::string(t) + "\")");
                        o.normals = *n;
                      }},
    MeshingOptionSpec{
        "presmooth", "FLOAT",
        "Gaussian sigma in mm applied to each part before extraction (0: off; costs volume)",
        [](const O& o) { return number_text(o.volume_sigma_mm); },
        [](O& o, std::string_view t) { o.volume_sigma_mm = number("presmooth", t); }},
    MeshingOptionSpec{
        "dc-svd-eps", "FLOAT",
        "Dual Contouring: drop QEF singular values below this fraction of the largest",
        [](const O& o) { return number_text(o.dc_svd_eps); },
        [](O& o, std::string_view t) { o.dc_svd_eps = number("dc-svd-eps", t); }},
    MeshingOptionSpec{
        "dc-tolerance", "FLOAT",
        "Dual Contouring: simplify flat regions up to this error in mm (0: off)",
        [](const O& o) { return number_text(o.dc_tolerance_mm); },
        [](O& o, std::string_view t) { o.dc_tolerance_mm = number("dc-tolerance", t); }},
    MeshingOptionSpec{"smooth", "TEXT", "smoothing: none, laplacian, hc, taubin or sinc",
                      [](const O& o) { return std::string(smooth_method_name(o.smooth.method)); },
                      [](O& o, std::string_view t) {
                        const auto m = parse_smooth_method(t);
                        if (!m) {
                          throw Error(
                              "--smooth must be none, laplacian, hc, taubin or sinc (got \"" +
                              std::string(t) + "\")");
                        }
                        o.smooth.method = *m;
                      }},
    MeshingOptionSpec{
        "iterations", "INT", "smoothing iterations (0: the method's default)",
        [](const O& o) { return std::to_string(o.smooth.iterations); },
        [](O& o, std::string_view t) { o.smooth.iterations = whole_number<int>("iterations", t); }},
    MeshingOptionSpec{"lambda", "FLOAT", "Laplacian step (1: move to the neighbour average)",
                      [](const O& o) { return number_text(o.smooth.lambda); },
                      [](O& o, std::string_view t) { o.smooth.lambda = number("lambda", t); }},
    MeshingOptionSpec{"alpha", "FLOAT", "HC: weight of the original positions",
                      [](const O& o) { return number_text(o.smooth.alpha); },
                      [](O& o, std::string_view t) { o.smooth.alpha = number("alpha", t); }},
    MeshingOptionSpec{"beta", "FLOAT", "HC: weight of a vertex's own correction",
                      [](const O& o) { return number_text(o.smooth.beta); },
                      [](O& o, std::string_view t) { o.smooth.beta = number("beta", t); }},
    MeshingOptionSpec{
        "taubin-lambda", "FLOAT", "Taubin: shrinking step",
        [](const O& o) { return number_text(o.smooth.taubin_lambda); },
        [](O& o, std::string_view t) { o.smooth.taubin_lambda = number("taubin-lambda", t); }},
    MeshingOptionSpec{
        "taubin-mu", "FLOAT", "Taubin: inflating step (negative)",
        [](const O& o) { return number_text(o.smooth.taubin_mu); },
        [](O& o, std::string_view t) { o.smooth.taubin_mu = number("taubin-mu", t); }},
    MeshingOptionSpec{
        "pass-band", "FLOAT", "windowed sinc: pass band (3D Slicer: 0.01)",
        [](const O& o) { return number_text(o.smooth.pass_band); },
        [](O& o, std::string_view t) { o.smooth.pass_band = number("pass-band", t); }},
    MeshingOptionSpec{
        "preserve-volume", "FLAG",
        "do not restore each part's volume after smoothing (the plain filter)",
        [](const O& o) { return std::string(o.smooth.preserve_volume ? "true" : "false"); },
        [](O& o, std::string_view t) { o.smooth.preserve_volume = flag("preserve-volume", t); }},
    MeshingOptionSpec{
        "unit-gain", "FLAG",
        "windowed sinc exactly as VTK and 3D Slicer (a slight scaling, f(0) != 1)",
        [](const O& o) { return std::string(o.smooth.sinc_unit_gain ? "true" : "false"); },
        [](O& o, std::string_view t) { o.smooth.sinc_unit_gain = flag("unit-gain", t); }},
    MeshingOptionSpec{
        "decimate-error", "FLOAT",
        "decimate while the quadric error stays below this many mm (0: off; the report measures "
        "the true distance)",
        [](const O& o) { return number_text(o.decimate.error_mm); },
        [](O& o, std::string_view t) { o.decimate.error_mm = number("decimate-error", t); }},
    MeshingOptionSpec{"max-triangles", "INT",
                      "decimate to at most this many triangles in all, shared by the parts in "
                      "proportion to their area (0: off; wins over --decimate-error)",
                      [](const O& o) { return std::to_string(o.decimate.max_triangles); },
                      [](O& o, std::string_view t) {
                        o.decimate.max_triangles = whole_number<int64_t>("max-triangles", t);
                      }},
    MeshingOptionSpec{"max-triangles-per-part", "INT",
                      "decimate every part to at most this many triangles (0: off; no part goes "
                      "below 32)",
                      [](const O& o) { return std::to_string(o.decimate.max_triangles_per_part); },
                      [](O& o, std::string_view t) {
                        o.decimate.max_triangles_per_part =
                            whole_number<int64_t>("max-triangles-per-part", t);
                      }},
};

}  // namespace

std::span<const MeshingOptionSpec> meshing_option_specs() {
  return kSpecs;
}

const MeshingOptionSpec* find_meshing_option(std::string_view name) {
  if (name.starts_with("--")) name.remove_prefix(2);
  for (const MeshingOptionSpec& s : kSpecs) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

}  // namespace segmesh
