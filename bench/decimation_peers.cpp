// segmesh's decimation against meshoptimizer (and any peer whose output is a folder of PLY files,
// such as VTK's vtkQuadricDecimation from bench/vtk_decimate.py) at equal triangle counts: one
// Markdown table of speed, distance to the undecimated parts, triangle shape, closedness and
// contacts. Run by bench/compare_decimation.sh (docs/DECIMATION.md, "Against meshoptimizer and
// VTK").
//   segmesh_decimation_peers LABELMAP [--peer NAME DIR SECONDS]...
//
// The scene is build_scene's with default options (conforming surfaces), undecimated. Every
// part's target is the triangle count segmesh's own `--decimate-error 0.2` leaves it. Rows:
//   - segmesh --decimate-error 0.2 and segmesh --max-triangles (the same total), by decimate_scene;
//   - meshopt_simplify per part to its target (target_error 1e-2 of the part's extent, no locks:
//     0.18 has only meshopt_SimplifyLockBorder and a closed shell has no border); parts it stops
//     short of their target are counted;
//   - meshopt_simplify per part with no target and its own error bound at 0.2 mm (its error is
//     relative to the part's extent: 0.2 / meshopt_simplifyScale), to compare at equal error;
//   - meshopt_simplifySloppy per part to its target;
//   - every --peer: DIR holds one PLY per part, named as `segmesh mesh LABELMAP -o DIR/` names
//     them (part_file_paths), decimated by the peer; SECONDS its own timing.
// Measures (the library's own): mesh_deviation of every part against its undecimated mesh
// (Hausdorff and p95: the largest over the parts; mean: the parts' means weighted by their
// triangles), radii ratio pooled over all parts' triangles and the slivers (radii ratio below
// 0.05), parts closed and manifold (measure_mesh: closed, no non-manifold vertex), and the
// contact gap: for every vertex of a contact of the undecimated surface more than 1 mm from the
// surface's other triangles, the nearest point of one part's decimated shell, and that point's
// distance to the other part's decimated shell, both ways; the largest. Shells decimated together
// as one surface (segmesh) give 0; shells decimated alone give two surfaces.
// Times: steady_clock, all in one run, so the ratios are of one machine state. A second table
// gives every part's Hausdorff distance per method.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <meshoptimizer.h>

#include "segmesh/decimation.hpp"
#include "segmesh/labelled_surface.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_mesh.hpp"

using namespace segmesh;

namespace {

using Clock = std::chrono::steady_clock;

// meshoptimizer reads the positions as packed floats.
static_assert(sizeof(Vec3f) == 3 * sizeof(float));

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct Row {
  std::string name;
  std::vector<TriMesh> parts;  // in scene order
  double seconds = 0;
  std::string note;
};

// The vertices used by the triangles, renumbered in order of first use (meshoptimizer returns
// indices into the whole input vertex array).
TriMesh compacted(const std::vector<Vec3f>& positions, const std::vector<uint32_t>& indices) {
  TriMesh out;
  std::vector<uint32_t> map(positions.size(), UINT32_MAX);
  out.indices.reserve(indices.size());
  for (uint32_t i : indices) {
    if (map[i] == UINT32_MAX) {
      map[i] = static_cast<uint32_t>(out.positions.size());
      out.positions.push_back(positions[i]);
    }
    out.indices.push_back(map[i]);
  }
  return out;
}

template <class Simplify>
Row meshopt_row(const std::string& name, const Scene& scene, const std::vector<int64_t>& targets,
                Simplify simplify) {
  Row row{name, {}, 0, ""};
  int short_parts = 0;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const TriMesh& m = scene.parts[p].mesh;
    std::vector<uint32_t> out(m.indices.size());
    const auto t0 = Clock::now();
    const size_t n = simplify(out.data(), m, size_t(targets[p]) * 3);
    row.seconds += seconds_since(t0);
    out.resize(n);
    if (int64_t(n / 3) > targets[p]) ++short_parts;
    row.parts.push_back(compacted(m.positions, out));
  }
  if (short_parts) row.note = std::to_string(short_parts) + " parts stopped short of their target";
  return row;
}

std::vector<TriMesh> meshes_of(const Scene& scene) {
  std::vector<TriMesh> out;
  for (const Part& p : scene.parts) out.push_back(p.mesh);
  return out;
}

// The largest contact gap (see the top of the file) of `parts` over the contacts of the
// undecimated conforming surface, measured from the contact's vertices farther than
// kAwayFromOtherSheetsMm from every other triangle of the surface (the other sheets meet a contact
// at its junction curves; a point next to one may find its nearest point on a part's own free
// sheet, which is not on the other part even where the two parts still share their contact).
constexpr double kAwayFromOtherSheetsMm = 1.0;

double contact_gap(const LabelledSurface& surface, const std::vector<TriMesh>& parts) {
  using Pair = std::pair<uint32_t, uint32_t>;
  std::map<Pair, std::vector<size_t>> contacts;  // the contact's triangles
  for (size_t t = 0; t < surface.sides.size(); ++t) {
    const auto [in, outside] = surface.sides[t];
    if (in > 0 && outside > 0) contacts[{std::min(in, outside), std::max(in, outside)}].push_back(t);
  }
  std::map<uint32_t, MeshDistance> shells;
  for (const auto& [pair, triangles] : contacts)
    for (uint32_t material : {pair.first, pair.second})
      if (!shells.count(material)) shells.emplace(material, MeshDistance(parts[material - 1]));
  double gap = 0;
  for (const auto& [pair, triangles] : contacts) {
    TriMesh others;
    others.positions = surface.mesh.positions;
    std::vector<bool> in_contact(surface.sides.size(), false);
    for (size_t t : triangles) in_contact[t] = true;
    for (size_t t = 0; t < surface.sides.size(); ++t)
      if (!in_contact[t])
        others.indices.insert(others.indices.end(), surface.mesh.indices.begin() + 3 * t,
                              surface.mesh.indices.begin() + 3 * t + 3);
    const MeshDistance away(others);
    std::vector<uint32_t> vertices;
    for (size_t t : triangles)
      vertices.insert(vertices.end(), surface.mesh.indices.begin() + 3 * t,
                      surface.mesh.indices.begin() + 3 * t + 3);
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    const MeshDistance& a = shells.at(pair.first);
    const MeshDistance& b = shells.at(pair.second);
    for (uint32_t v : vertices) {
      const Vec3d p = to_double(surface.mesh.positions[v]);
      if (away.distance(p) <= kAwayFromOtherSheetsMm) continue;
      gap = std::max({gap, b.distance(a.closest_point(p)), a.distance(b.closest_point(p))});
    }
  }
  return gap;
}

std::string thousands(int64_t n) {
  const std::string digits = std::to_string(n);
  std::string s;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s += ' ';
    s += digits[i];
  }
  return s;
}

// Prints the row; returns every part's Hausdorff distance.
std::vector<double> print_row(const Row& row, const Scene& base, double segmesh_seconds) {
  std::vector<double> part_hausdorff;
  int64_t triangles = 0, slivers = 0, closed = 0, open_edges = 0, pinched = 0;
  double hausdorff = 0, p95 = 0, mean_sum = 0, rho_sum = 0;
  for (size_t p = 0; p < row.parts.size(); ++p) {
    const TriMesh& m = row.parts[p];
    const int64_t t = int64_t(m.triangle_count());
    triangles += t;
    const Deviation d = mesh_deviation(m, base.parts[p].mesh);
    hausdorff = std::max(hausdorff, d.hausdorff);
    part_hausdorff.push_back(d.hausdorff);
    p95 = std::max(p95, d.p95);
    mean_sum += d.mean * double(t);
    rho_sum += triangle_quality(m).mean * double(t);
    for (size_t k = 0; k < m.triangle_count(); ++k) {
      const double rho = radii_ratio(to_double(m.positions[m.indices[3 * k]]),
                                     to_double(m.positions[m.indices[3 * k + 1]]),
                                     to_double(m.positions[m.indices[3 * k + 2]]));
      if (rho < 0.05) ++slivers;
    }
    const MeshMeasures mm = measure_mesh(m);
    if (mm.closed() && mm.nonmanifold_vertices == 0) ++closed;
    if (!mm.closed()) ++open_edges;
    if (mm.nonmanifold_vertices > 0) ++pinched;
  }
  std::string note = row.note;
  if (open_edges || pinched) {
    if (!note.empty()) note += "; ";
    note += std::to_string(open_edges) + " parts with open or non-manifold edges, " +
            std::to_string(pinched) + " with non-manifold vertices";
  }
  const double gap = base.surface ? contact_gap(*base.surface, row.parts) : 0;
  char time[64] = "-", ratio[64] = "-";
  if (row.seconds > 0) {
    std::snprintf(time, sizeof time, "%.2f", row.seconds);
    std::snprintf(ratio, sizeof ratio, "%.2f", segmesh_seconds / row.seconds);
  }
  std::printf("| %s | %s | %.3f | %.3f | %.4f | %.3f | %s | %lld / %zu | %.3f | %s | %s | %s |\n",
              row.name.c_str(), thousands(triangles).c_str(), hausdorff, p95,
              triangles ? mean_sum / double(triangles) : 0.0, triangles ? rho_sum / double(triangles) : 0.0,
              thousands(slivers).c_str(), static_cast<long long>(closed), row.parts.size(), gap,
              time, ratio,
              note.c_str());
  std::fflush(stdout);
  return part_hausdorff;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: segmesh_decimation_peers LABELMAP [--peer NAME DIR SECONDS]...\n");
    return 2;
  }
  struct Peer {
    std::string name, dir;
    double seconds;
  };
  std::vector<Peer> peers;
  for (int a = 2; a < argc; ++a) {
    if (std::string(argv[a]) == "--peer" && a + 3 < argc) {
      peers.push_back({argv[a + 1], argv[a + 2], std::atof(argv[a + 3])});
      a += 3;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", argv[a]);
      return 2;
    }
  }
  const Image image = read_volume(argv[1]);
  const Scene base = build_scene(image, MeshingOptions{});

  std::vector<Row> rows;
  rows.push_back({"undecimated (default options)", meshes_of(base), 0, ""});

  Scene by_error = base;
  auto t0 = Clock::now();
  decimate_scene(by_error, DecimateOptions{.error_mm = 0.2});
  const double segmesh_seconds = seconds_since(t0);
  rows.push_back({"segmesh `--decimate-error 0.2`", meshes_of(by_error), segmesh_seconds, ""});
  std::vector<int64_t> targets;
  int64_t total = 0;
  for (const Part& p : by_error.parts) {
    targets.push_back(int64_t(p.mesh.triangle_count()));
    total += targets.back();
  }

  Scene by_budget = base;
  t0 = Clock::now();
  decimate_scene(by_budget, DecimateOptions{.max_triangles = total});
  rows.push_back({"segmesh `--max-triangles " + std::to_string(total) + "`", meshes_of(by_budget),
                  seconds_since(t0), ""});

  rows.push_back(meshopt_row("meshopt_simplify (error 1e-2)", base, targets,
                             [](uint32_t* out, const TriMesh& m, size_t target) {
                               return meshopt_simplify(out, m.indices.data(), m.indices.size(),
                                                       &m.positions[0].x, m.positions.size(),
                                                       sizeof(Vec3f), target, 1e-2f, 0, nullptr);
                             }));
  // The same at segmesh's error instead of its counts: no triangle target, meshoptimizer's own
  // error bound (relative to the part's extent, meshopt_simplifyScale) set to 0.2 mm.
  std::vector<int64_t> none(targets.size(), 0);
  rows.push_back(meshopt_row("meshopt_simplify (error 0.2 mm, no target)", base, none,
                             [](uint32_t* out, const TriMesh& m, size_t) {
                               const float scale = meshopt_simplifyScale(
                                   &m.positions[0].x, m.positions.size(), sizeof(Vec3f));
                               return meshopt_simplify(out, m.indices.data(), m.indices.size(),
                                                       &m.positions[0].x, m.positions.size(),
                                                       sizeof(Vec3f), 0, 0.2f / scale, 0, nullptr);
                             }));
  rows.back().note.clear();  // no target to stop short of
  rows.push_back(meshopt_row("meshopt_simplifySloppy", base, targets,
                             [](uint32_t* out, const TriMesh& m, size_t target) {
                               return meshopt_simplifySloppy(
                                   out, m.indices.data(), m.indices.size(), &m.positions[0].x,
                                   m.positions.size(), sizeof(Vec3f), target, 1.0f, nullptr);
                             }));

  const std::vector<std::filesystem::path> files =
      part_file_paths(base, "", MeshFormat::ply);
  for (const Peer& peer : peers) {
    Row row{peer.name, {}, peer.seconds, ""};
    for (const auto& file : files) {
      const Scene read = read_mesh(std::filesystem::path(peer.dir) / file);
      TriMesh all;
      for (const Part& p : read.parts) {
        const uint32_t offset = uint32_t(all.positions.size());
        all.positions.insert(all.positions.end(), p.mesh.positions.begin(), p.mesh.positions.end());
        for (uint32_t i : p.mesh.indices) all.indices.push_back(offset + i);
      }
      row.parts.push_back(std::move(all));
    }
    rows.push_back(std::move(row));
  }

  int64_t undecimated = 0;
  for (const Part& p : base.parts) undecimated += int64_t(p.mesh.triangle_count());
  std::printf("Targets: every part the triangles segmesh `--decimate-error 0.2` leaves it (%s in "
              "all, %zu parts, %s undecimated).\n\n",
              thousands(total).c_str(), base.parts.size(), thousands(undecimated).c_str());
  std::printf("| run | triangles | Hausdorff max (mm) | p95 max (mm) | mean (mm) | mean radii ratio "
              "| slivers (< 0.05) | parts closed | contact gap (mm) | time (s) | segmesh 0.2 time / "
              "this | note |\n");
  std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n");
  std::vector<std::vector<double>> hausdorff;
  for (const Row& row : rows) hausdorff.push_back(print_row(row, base, segmesh_seconds));

  // Per part: where each method's largest distance is.
  std::printf("\nHausdorff distance (mm) per part:\n\n| part | undecimated | target |");
  for (size_t r = 1; r < rows.size(); ++r) std::printf(" %s |", rows[r].name.c_str());
  std::printf("\n| --- | ---: | ---: |");
  for (size_t r = 1; r < rows.size(); ++r) std::printf(" ---: |");
  for (size_t p = 0; p < base.parts.size(); ++p) {
    std::printf("\n| %s | %s | %s |", base.parts[p].name.c_str(),
                thousands(int64_t(base.parts[p].mesh.triangle_count())).c_str(),
                thousands(targets[p]).c_str());
    for (size_t r = 1; r < rows.size(); ++r) std::printf(" %.3f |", hausdorff[r][p]);
  }
  std::printf("\n");
  return 0;
}
