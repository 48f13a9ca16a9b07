// Prints a Markdown table of what each smoothing method does to a voxelised sphere: the volume
// against the unsmoothed mesh and against the true ball, and the distance of the vertices to the
// true sphere (RMS, largest, mean signed: negative = inside, i.e. shrinkage). The sphere is a 0/1
// label map of the ball |x - c| <= R sampled at voxel centres on an anisotropic grid placed ~500 mm
// from the world origin (as CT is), meshed by Marching Cubes exactly as the pipeline meshes a part.
//
//   segmesh_smoothing_sphere [--radius MM] [--spacing SX,SY,SZ] [--centre X,Y,Z]
//                            [--write LABELMAP.nii.gz] [--stl NAME=FILE]... [--ras]
//                            [--check sinc|laplacian UNSMOOTHED.stl SMOOTHED.stl]
//
// --write    saves the label map (any format write_volume knows) for other tools, e.g.
//            ../shared/tools/peer_mesh.py (bench/compare_sphere_vtk.sh does both).
// --stl      scores a mesh file (STL, PLY, OBJ, GLB; all parts together) in the same table.
// --ras      the --stl and --check files are in RAS (as peer_mesh.py --frame world writes NIfTI
//            world coordinates): x and y are negated to get our LPS frame.
// --check    runs segmesh's windowed sinc (20 iterations, pass band 0.01: peer_mesh.py's
//            vtk_discrete_flying_edges_sinc) or Laplacian (lambda 1, 2 iterations: its
//            vtk_laplacian_r1.0) on UNSMOOTHED and compares the result vertex by vertex with
//            SMOOTHED (VTK's result on the same mesh). The sinc filters agree to float rounding;
//            the Laplacians do not: vtkSmoothPolyDataFilter updates the points in place, in point
//            order (the sequential variant), ours simultaneously as the reference describes.
//            May be given more than once.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/smoothing.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_volume.hpp"

using namespace segmesh;

namespace {

struct Sphere {
  Vec3d centre{120.25, -310.4, 415.7};  // LPS mm, |c| ~ 530 mm
  double radius = 20;
  std::array<double, 3> spacing{0.5, 0.5, 1.0};
};

// The label map: 1 where the voxel centre is inside the ball, with 3 voxels of background around
// it (the pipeline's crops have 2).
LabelVolume sphere_labels(const Sphere& s) {
  LabelVolume v;
  // Origin on a round number below c - half, so the centre sits at a generic offset in its voxel.
  const double c[3] = {s.centre.x, s.centre.y, s.centre.z};
  for (int a = 0; a < 3; ++a) {
    const double half = s.radius + 3 * s.spacing[a];
    v.grid.spacing[a] = s.spacing[a];
    v.grid.origin[a] = std::floor(c[a] - half);
    v.grid.dims[a] =
        static_cast<int64_t>(std::ceil((c[a] + half - v.grid.origin[a]) / s.spacing[a])) + 1;
  }
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 0; k < v.grid.dims[2]; ++k)
    for (int64_t j = 0; j < v.grid.dims[1]; ++j)
      for (int64_t i = 0; i < v.grid.dims[0]; ++i)
        if (norm(v.grid.to_world({double(i), double(j), double(k)}) - s.centre) <= s.radius)
          v.at(i, j, k) = 1;
  return v;
}

TriMesh mesh_labels(const LabelVolume& labels) {
  Volume<uint8_t> field;
  field.grid = labels.grid;
  field.voxels.assign(labels.voxels.begin(), labels.voxels.end());
  return marching_cubes(field, McOptions{});
}

struct Score {
  int64_t vertices = 0;
  double volume = 0, rms = 0, max = 0, mean = 0, rho_mean = 0;
  bool closed = false;
};

Score score(const TriMesh& mesh, const Sphere& s) {
  Score r;
  const MeshMeasures m = measure_mesh(mesh);
  r.vertices = m.vertices;
  r.volume = m.volume_mm3;
  r.closed = m.closed();
  r.rho_mean = triangle_quality(mesh).mean;
  std::vector<char> used(mesh.positions.size(), 0);
  for (uint32_t i : mesh.indices) used[i] = 1;
  double sum2 = 0, sum = 0;
  int64_t n = 0;
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!used[i]) continue;
    const double d = norm(to_double(mesh.positions[i]) - s.centre) - s.radius;
    sum2 += d * d;
    sum += d;
    r.max = std::max(r.max, std::abs(d));
    ++n;
  }
  r.rms = n ? std::sqrt(sum2 / double(n)) : 0;
  r.mean = n ? sum / double(n) : 0;
  return r;
}

void print_header() {
  std::printf(
      "| mesh | setting | vertices | volume vs unsmoothed | volume vs ball | RMS distance mm | "
      "max distance mm | mean signed mm | rho mean | closed | smooth ms |\n");
  std::printf("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n");
}

void print_row(const std::string& mesh, const std::string& setting, const Score& r,
               double unsmoothed_volume, double ball_volume, double ms) {
  char time[32] = "";
  if (ms >= 0) std::snprintf(time, sizeof time, "%.1f", ms);
  std::printf("| %s | %s | %lld | %+.3f %% | %+.3f %% | %.4f | %.4f | %+.4f | %.3f | %s | %s |\n",
              mesh.c_str(), setting.c_str(), (long long)r.vertices,
              100 * (r.volume / unsmoothed_volume - 1), 100 * (r.volume / ball_volume - 1), r.rms,
              r.max, r.mean, r.rho_mean, r.closed ? "yes" : "NO", time);
}

TriMesh read_all_parts(const std::string& path, bool ras) {
  const Scene scene = read_mesh(path);
  TriMesh all;
  for (const Part& p : scene.parts) {
    const uint32_t base = static_cast<uint32_t>(all.positions.size());
    all.positions.insert(all.positions.end(), p.mesh.positions.begin(), p.mesh.positions.end());
    for (uint32_t i : p.mesh.indices) all.indices.push_back(base + i);
  }
  if (ras)
    for (Vec3f& p : all.positions) p = {-p.x, -p.y, p.z};
  return all;
}

std::array<double, 3> parse3(const char* text) {
  std::array<double, 3> v{};
  if (std::sscanf(text, "%lf,%lf,%lf", &v[0], &v[1], &v[2]) != 3) {
    std::fprintf(stderr, "expected X,Y,Z, got %s\n", text);
    std::exit(2);
  }
  return v;
}

int usage() {
  std::fprintf(stderr,
               "usage: segmesh_smoothing_sphere [--radius MM] [--spacing SX,SY,SZ] "
               "[--centre X,Y,Z] [--write FILE] [--stl NAME=FILE]... [--ras] "
               "[--check sinc|laplacian UNSMOOTHED.stl SMOOTHED.stl]...\n");
  return 2;
}

int run(int argc, char** argv) {
  Sphere s;
  std::string write_path;
  struct Check {
    std::string method, unsmoothed, smoothed;
  };
  std::vector<Check> checks;
  std::vector<std::pair<std::string, std::string>> stls;
  bool ras = false;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool has_value = a + 1 < argc;
    if (arg == "--radius" && has_value) {
      s.radius = std::atof(argv[++a]);
    } else if (arg == "--spacing" && has_value) {
      s.spacing = parse3(argv[++a]);
    } else if (arg == "--centre" && has_value) {
      const auto c = parse3(argv[++a]);
      s.centre = {c[0], c[1], c[2]};
    } else if (arg == "--write" && has_value) {
      write_path = argv[++a];
    } else if (arg == "--stl" && has_value) {
      const std::string v = argv[++a];
      const size_t eq = v.find('=');
      if (eq == std::string::npos) return usage();
      stls.emplace_back(v.substr(0, eq), v.substr(eq + 1));
    } else if (arg == "--ras") {
      ras = true;
    } else if (arg == "--check" && a + 3 < argc) {
      Check c{argv[a + 1], argv[a + 2], argv[a + 3]};
      if (c.method != "sinc" && c.method != "laplacian") return usage();
      checks.push_back(c);
      a += 3;
    } else {
      return usage();
    }
  }
  if (!(s.radius > 0) || !(s.spacing[0] > 0 && s.spacing[1] > 0 && s.spacing[2] > 0))
    return usage();

  const LabelVolume labels = sphere_labels(s);
  if (!write_path.empty()) write_volume(labels, write_path);
  const TriMesh unsmoothed = mesh_labels(labels);
  const Score base = score(unsmoothed, s);
  const double ball = 4.0 / 3.0 * std::numbers::pi * s.radius * s.radius * s.radius;
  int64_t inside = 0;
  for (int32_t v : labels.voxels) inside += v;
  std::printf(
      "Sphere radius %.2f mm, centre (%.2f, %.2f, %.2f) mm LPS, spacing %.3g x %.3g x %.3g mm, "
      "grid %lld x %lld x %lld; voxel volume vs ball %+.3f %%.\n\n",
      s.radius, s.centre.x, s.centre.y, s.centre.z, s.spacing[0], s.spacing[1], s.spacing[2],
      (long long)labels.grid.dims[0], (long long)labels.grid.dims[1],
      (long long)labels.grid.dims[2],
      100 * (double(inside) * labels.grid.voxel_volume() / ball - 1));
  print_header();
  print_row("segmesh MC", "unsmoothed", base, base.volume, ball, -1);

  struct Setting {
    SmoothOptions options;
    std::string label;
  };
  std::vector<Setting> settings;
  for (int it : {2, 4, 5})
    settings.push_back({{.method = SmoothMethod::laplacian, .iterations = it, .preserve_volume = false},
                        "laplacian, lambda 1, " + std::to_string(it) + " it"});
  for (int it : {2, 4, 5})
    settings.push_back({{.method = SmoothMethod::hc, .iterations = it, .preserve_volume = false},
                        "hc, alpha 0, beta 0.5, " + std::to_string(it) + " it"});
  for (int it : {10, 20, 40, 50, 100})
    settings.push_back({{.method = SmoothMethod::taubin, .iterations = it, .preserve_volume = false},
                        "taubin 0.5024/-0.5289, " + std::to_string(it) + " it"});
  for (bool unit : {false, true})
    for (double pb : {0.1, 0.01, 0.001})
      for (int it : {20, 40}) {
        char label[80];
        std::snprintf(label, sizeof label, "sinc%s, pass band %g, %d it", unit ? " unit gain" : " (VTK)",
                      pb, it);
        settings.push_back(
            {{.method = SmoothMethod::sinc, .iterations = it, .pass_band = pb, .sinc_unit_gain = unit,
              .preserve_volume = false},
             label});
      }
  // segmesh's default: windowed sinc with unit gain and the volume restored.
  settings.push_back({default_smoothing(), "segmesh default (sinc unit gain, 0.01, 20 it, volume kept)"});
  for (const Setting& setting : settings) {
    TriMesh mesh;
    double best_ms = 1e300;
    for (int repeat = 0; repeat < 3; ++repeat) {
      mesh = unsmoothed;
      const auto t0 = std::chrono::steady_clock::now();
      smooth_mesh(mesh, setting.options);
      const auto t1 = std::chrono::steady_clock::now();
      best_ms = std::min(best_ms, std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
    print_row("segmesh MC", setting.label, score(mesh, s), base.volume, ball, best_ms);
  }
  for (const auto& [name, path] : stls)
    print_row(name, "file", score(read_all_parts(path, ras), s), base.volume, ball, -1);

  for (const Check& check : checks) {
    TriMesh ours = read_all_parts(check.unsmoothed, ras);
    const TriMesh theirs = read_all_parts(check.smoothed, ras);
    if (ours.indices != theirs.indices || ours.positions.size() != theirs.positions.size()) {
      std::printf("\n--check %s: the two files do not share their connectivity\n",
                  check.method.c_str());
      return 1;
    }
    const bool sinc = check.method == "sinc";
    smooth_mesh(
        ours,
        sinc ? SmoothOptions{.method = SmoothMethod::sinc, .iterations = 20, .pass_band = 0.01,
                             .sinc_unit_gain = false, .preserve_volume = false}
             : SmoothOptions{.method = SmoothMethod::laplacian, .iterations = 2, .lambda = 1.0,
                             .preserve_volume = false});
    double max = 0, sum2 = 0;
    for (size_t i = 0; i < ours.positions.size(); ++i) {
      const double d = norm(to_double(ours.positions[i]) - to_double(theirs.positions[i]));
      max = std::max(max, d);
      sum2 += d * d;
    }
    std::printf(
        "\nsegmesh %s on %s vs VTK's result %s: %zu vertices, max difference %.2e mm, RMS "
        "%.2e mm\n",
        sinc ? "sinc (pass band 0.01, 20 it)" : "laplacian (lambda 1, 2 it)",
        check.unsmoothed.c_str(), check.smoothed.c_str(), ours.positions.size(), max,
        std::sqrt(sum2 / double(std::max<size_t>(1, ours.positions.size()))));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "segmesh_smoothing_sphere: error: %s\n", e.what());
    return 2;
  }
}
