// segmesh quality MESH [--json]: whether a mesh file can be trusted — per part and for all parts
// together: size, area, enclosed volume, mean edge length, triangle quality (radii ratio) and the
// topology checks (boundary and non-manifold edges, non-manifold vertices, winding, Euler
// characteristic, shells).
//
// The definitions are those of ../shared/tools/mesh_metrics.py, the script that scores every
// program's meshes in the comparison tables, and "all parts" is the file read as one mesh, as that
// script reads it: its numbers are the script's numbers for the same STL, PLY or OBJ file. Notably:
// vertices are those some triangle uses; STL corners with identical coordinates are one vertex,
// across solids too; shells are connected through shared vertices; a triangle is degenerate when
// its radii ratio is below 1e-6; the 1st percentile interpolates as numpy does. "closed" is
// stricter than the script's: it also requires consistent winding (no winding errors), as
// everywhere in segmesh.
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "segmesh/label_info.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_mesh.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct QualityArgs {
  std::string input;
  bool json = false;
};

// mesh_metrics.py's n_degenerate: zero area or collinear to working precision.
constexpr double kDegenerateRho = 1e-6;

struct MeshQuality {
  MeshMeasures measures;
  QualityStats rho;
  int64_t degenerate = 0;  // triangles with rho < kDegenerateRho
};

MeshQuality assess(const TriMesh& mesh) {
  MeshQuality q;
  q.measures = measure_mesh(mesh);
  q.rho = triangle_quality(mesh);
  q.degenerate = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, mesh.triangle_count()), int64_t{0},
      [&](const tbb::blocked_range<size_t>& r, int64_t n) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
          const uint32_t* v = &mesh.indices[3 * t];
          n += radii_ratio(to_double(mesh.positions[v[0]]), to_double(mesh.positions[v[1]]),
                           to_double(mesh.positions[v[2]])) < kDegenerateRho;
        }
        return n;
      },
      std::plus<>());
  return q;
}

// The format read_mesh reads `file` as (the same dispatch as read_mesh.cpp): the glTF and PLY
// magics, then the extension, else STL.
MeshFormat format_read_as(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  char head[5] = {};
  in.read(head, sizeof head);
  const std::string_view h(head, static_cast<size_t>(in.gcount()));
  if (h.starts_with("glTF")) return MeshFormat::glb;
  if (h.starts_with("ply\n") || h.starts_with("ply\r\n")) return MeshFormat::ply;
  return mesh_format_from_path(file).value_or(MeshFormat::stl);
}

// A part's mesh where the file places it: a rigid node transform (glTF) applied, if any, into
// `storage`; otherwise the part's own mesh, not copied. Rigid motions change none of the measures
// of a closed mesh, but an open mesh's volume is taken about the origin.
const TriMesh& placed_mesh(const Part& part, TriMesh& storage) {
  if (is_identity(part.transform)) return part.mesh;
  const Transform& t = part.transform;  // column-major
  storage.indices = part.mesh.indices;
  storage.positions.clear();
  for (const Vec3f& p : part.mesh.positions) {
    storage.positions.push_back(to_float(transform_point(t, to_double(p))));
  }
  return storage;
}

// Merges vertices with bit-identical coordinates (+0 and -0 alike), as the STL reader does within
// a solid and mesh_metrics.py does over the whole file. Sorting, not hashing: no tuning, and the
// result does not depend on the order of the parts.
void weld_identical_positions(TriMesh& mesh) {
  const auto bits = [](float v) {
    if (v == 0.0f) v = 0.0f;
    uint32_t b;
    std::memcpy(&b, &v, 4);
    return b;
  };
  std::vector<std::array<uint32_t, 4>> keys(mesh.positions.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    keys[i] = {bits(p.x), bits(p.y), bits(p.z), static_cast<uint32_t>(i)};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<uint32_t> new_index(keys.size());
  std::vector<Vec3f> positions;
  for (size_t k = 0; k < keys.size(); ++k) {
    if (k == 0 || !std::equal(keys[k].begin(), keys[k].begin() + 3, keys[k - 1].begin())) {
      positions.push_back(mesh.positions[keys[k][3]]);
    }
    new_index[keys[k][3]] = static_cast<uint32_t>(positions.size() - 1);
  }
  for (uint32_t& i : mesh.indices) i = new_index[i];
  mesh.positions = std::move(positions);
  mesh.normals.clear();
  mesh.colors.clear();
}

// Every part in one mesh, as mesh_metrics.py reads the file.
TriMesh all_parts(const std::vector<const TriMesh*>& meshes, bool weld) {
  TriMesh all;
  for (const TriMesh* mesh : meshes) {
    const TriMesh& m = *mesh;
    const auto offset = static_cast<uint32_t>(all.positions.size());
    all.positions.insert(all.positions.end(), m.positions.begin(), m.positions.end());
    for (uint32_t i : m.indices) all.indices.push_back(i + offset);
  }
  if (weld) weld_identical_positions(all);
  return all;
}

using Json = nlohmann::ordered_json;  // keys in the order written: the file reads top-down

// One mesh's numbers; those with no meaning without triangles are null then.
Json quality_json(const MeshQuality& q) {
  const MeshMeasures& m = q.measures;
  const bool any = m.triangles > 0;
  const auto number = [any](double v) { return any ? Json(v) : Json(nullptr); };
  return {{"vertices", m.vertices},
          {"triangles", m.triangles},
          {"edges", m.edges},
          {"area_mm2", m.area_mm2},
          {"volume_mm3", m.volume_mm3},
          {"mean_edge_length_mm", number(m.mean_edge_length_mm)},
          {"radii_ratio",
           {{"min", number(q.rho.min)},
            {"mean", number(q.rho.mean)},
            {"p01", number(q.rho.p01)},
            {"histogram", q.rho.histogram},
            {"degenerate", q.degenerate}}},
          {"boundary_edges", m.boundary_edges},
          {"nonmanifold_edges", m.nonmanifold_edges},
          {"nonmanifold_vertices", m.nonmanifold_vertices},
          {"winding_errors", m.winding_errors},
          {"euler", m.euler},
          {"shells", m.shells},
          {"closed", m.closed()}};
}

void print_tables(const std::vector<std::string>& names, const std::vector<MeshQuality>& rows,
                  const MeshQuality& histogram_of) {
  std::printf("\n%-24s %9s %10s %13s %14s %8s %8s %8s %8s %8s\n", "part", "vertices", "triangles",
              "area_mm2", "volume_mm3", "edge_mm", "rho_min", "rho_mean", "rho_p01", "rho<1e-6");
  for (size_t r = 0; r < rows.size(); ++r) {
    const MeshMeasures& m = rows[r].measures;
    const QualityStats& s = rows[r].rho;
    std::printf("%-24s %9lld %10lld %13.2f %14.2f %8.4f %8.4f %8.4f %8.4f %8lld\n",
                names[r].c_str(), (long long)m.vertices, (long long)m.triangles, m.area_mm2,
                m.volume_mm3, m.mean_edge_length_mm, s.min, s.mean, s.p01,
                (long long)rows[r].degenerate);
  }
  std::printf("\n%-24s %9s %9s %11s %8s %6s %6s %6s\n", "part", "boundary", "nm_edges",
              "nm_vertices", "winding", "euler", "shells", "closed");
  for (size_t r = 0; r < rows.size(); ++r) {
    const MeshMeasures& m = rows[r].measures;
    std::printf("%-24s %9lld %9lld %11lld %8lld %6lld %6lld %6s\n", names[r].c_str(),
                (long long)m.boundary_edges, (long long)m.nonmanifold_edges,
                (long long)m.nonmanifold_vertices, (long long)m.winding_errors, (long long)m.euler,
                (long long)m.shells, m.closed() ? "yes" : "NO");
  }
  std::printf("\nradii ratio histogram (%s), triangles per bin:\n",
              rows.size() > 1 ? "all parts" : names[0].c_str());
  for (int k = 0; k < 10; ++k) std::printf("  %.1f-%.1f", k / 10.0, (k + 1) / 10.0);
  std::printf("\n");
  for (int k = 0; k < 10; ++k) std::printf(" %8lld", (long long)histogram_of.rho.histogram[k]);
  std::printf("\n");
}

int run_quality(const QualityArgs& args) {
  const Scene scene = read_mesh(args.input);
  const MeshFormat format = format_read_as(args.input);

  std::vector<TriMesh> moved(scene.parts.size());
  std::vector<const TriMesh*> meshes;
  std::vector<MeshQuality> parts;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    meshes.push_back(&placed_mesh(scene.parts[p], moved[p]));
    parts.push_back(assess(*meshes.back()));
  }
  // One part is the whole file already (an STL solid is welded by the reader).
  const MeshQuality all =
      parts.size() == 1 ? parts[0] : assess(all_parts(meshes, format == MeshFormat::stl));

  if (args.json) {
    Json j = {{"file", args.input}, {"format", extension(format)}};
    j["parts"] = Json::array();
    for (size_t p = 0; p < parts.size(); ++p) {
      const Part& part = scene.parts[p];
      Json row = {
          {"name", part.name}, {"label", part.label}, {"role", std::string(role_name(part.role))}};
      row.update(quality_json(parts[p]));
      j["parts"].push_back(std::move(row));
    }
    j["all"] = quality_json(all);
    j["all"]["parts"] = parts.size();
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }

  std::printf(
      "%s: %s, %zu part%s%s\n", args.input.c_str(), std::string(extension(format)).c_str(),
      parts.size(), parts.size() == 1 ? "" : "s",
      format == MeshFormat::stl ? " (corners with identical coordinates are one vertex)" : "");
  std::vector<std::string> names;
  std::vector<MeshQuality> rows = parts;
  for (const Part& part : scene.parts) names.push_back(part.name);
  if (parts.size() != 1) {
    names.push_back("all parts");
    rows.push_back(all);
  }
  print_tables(names, rows, all);
  return 0;
}

}  // namespace

Subcommand add_quality_command(CLI::App& app) {
  auto args = std::make_shared<QualityArgs>();
  CLI::App* cmd = app.add_subcommand(
      "quality",
      "Measure a mesh file per part and as a whole: area, volume, radii ratio, closedness, "
      "non-manifold edges and vertices, winding, Euler characteristic, shells");
  cmd->add_option("mesh", args->input, "mesh file: .stl, .ply, .obj or .glb")->required();
  cmd->add_flag("--json", args->json, "print JSON");
  return {cmd, [args] { return run_quality(*args); }};
}

}  // namespace segmesh::cli
