#include "segmesh/joint_smoothing.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/detail/smoothing_sweeps.hpp"
#include "segmesh/detail/surface_roles.hpp"
#include "segmesh/detail/volume_restoration.hpp"

namespace segmesh {

namespace {

// A sum per material over the triangles (T: a VolumeCubic, or anything with + and a zero
// T{}): add(t, of) adds triangle t's terms to of(material). Fixed blocks of triangles, added in
// block order, so the result does not depend on the number of threads. A block keeps the sums of
// the materials its triangles touch, not one per part: on a 32^3 map of random labels (31 176
// parts) a dense array of cubics per block meant zeroing and adding 120 MB.
template <class T, class AddTriangle>
std::vector<T> material_sums(size_t triangles, size_t materials, AddTriangle&& add) {
  const size_t blocks = (triangles + kTriangleBlock - 1) / kTriangleBlock;
  // Per block: (material, sum) for the materials met, ascending.
  std::vector<std::vector<std::pair<uint32_t, T>>> partial(blocks);
  struct Scratch {
    std::vector<T> of;
    std::vector<uint64_t> block;  // per material: the block (+ 1) that last met it
    std::vector<uint32_t> met;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([&] {
    return Scratch{std::vector<T>(materials), std::vector<uint64_t>(materials, 0), {}};
  });
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    Scratch& s = scratch.local();
    // A material's cubic starts at zero when the block first meets it, as a fresh sum would.
    auto of = [&](uint32_t m) -> T& {
      if (s.block[m] != b + 1) {
        s.block[m] = b + 1;
        s.of[m] = T{};
        s.met.push_back(m);
      }
      return s.of[m];
    };
    for (size_t t = b * kTriangleBlock, end = std::min(triangles, (b + 1) * kTriangleBlock);
         t < end; ++t)
      add(t, of);
    std::sort(s.met.begin(), s.met.end());
    partial[b].reserve(s.met.size());
    for (uint32_t m : s.met) partial[b].push_back({m, s.of[m]});
    s.met.clear();
  });
  std::vector<T> total(materials);
  for (const auto& block : partial)
    for (const auto& [m, c] : block) total[m] = total[m] + c;
  return total;
}

// A part enclosed by other parts keeps its volume only through them: the volume restoration moves
// background-facing vertices, and it has none. Smoothing can flatten such a part when it is a
// voxel or two (measured: single voxels of random label noise with Dual Contouring, whose vertices
// there are all sheet vertices of one contact, smoothed to zero or slightly negative volume). A
// part left with less than this fraction of its extracted volume gets its vertices back where they
// were extracted; the surface stays one, so its contacts stay exact. Only the parts in `check`
// (by material) are looked at: a part whose volume the restoration gave back (its cubic at the
// solved offset) is left out, since the fold repair after it only moves vertices part of the way
// back toward where they were extracted.
constexpr double kCollapsedVolume = 0.25;

void restore_collapsed_parts(LabelledSurface& surface, const std::vector<Vec3f>& original,
                             const std::vector<char>& check) {
  TriMesh& mesh = surface.mesh;
  struct Volumes {  // 6 times the enclosed volume, smoothed and extracted
    double now = 0, before = 0;
    Volumes operator+(const Volumes& o) const { return {now + o.now, before + o.before}; }
  };
  auto volume = [](Vec3f a, Vec3f b, Vec3f c) {
    return dot(to_double(a), cross(to_double(b), to_double(c)));
  };
  const size_t nt = surface.sides.size();
  const std::vector<Volumes> v =
      material_sums<Volumes>(nt, surface.part_count + 1, [&](size_t t, auto&& of) {
        const auto [inside, outside] = surface.sides[t];
        if (!check[inside] && !check[outside]) return;
        const uint32_t* x = &mesh.indices[3 * t];
        const double now = volume(mesh.positions[x[0]], mesh.positions[x[1]], mesh.positions[x[2]]);
        const double before = volume(original[x[0]], original[x[1]], original[x[2]]);
        Volumes& in = of(inside);
        in.now += now, in.before += before;
        Volumes& out = of(outside);
        out.now -= now, out.before -= before;
      });
  std::vector<char> collapsed(v.size(), 0);
  bool any = false;
  for (size_t m = 1; m < v.size(); ++m)
    any |= collapsed[m] = check[m] && v[m].before > 0 && v[m].now < kCollapsedVolume * v[m].before;
  if (!any) return;
  for (size_t t = 0; t < nt; ++t) {
    const auto [inside, outside] = surface.sides[t];
    if (!collapsed[inside] && !collapsed[outside]) continue;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.indices[3 * t + size_t(c)];
      mesh.positions[v] = original[v];
    }
  }
}

}  // namespace

void smooth_jointly(LabelledSurface& surface, const SmoothOptions& options, Progress& progress) {
  if (const auto problem = smooth_options_problem(options)) {
    throw std::invalid_argument("smooth_jointly: " + std::string(problem->option) + " " +
                                problem->rule);
  }
  TriMesh& mesh = surface.mesh;
  if (options.method == SmoothMethod::none || mesh.positions.empty()) return;
  const int iterations =
      options.iterations > 0 ? options.iterations : default_smooth_iterations(options.method);
  const size_t nv = mesh.positions.size();
  const std::vector<uint32_t>& idx = mesh.indices;
  const Triangles triangles{idx.data(), triangle_chunks(idx)};
  // Both windings of one contact ((1, 2) and (2, 1), which multi-label Marching Cubes mixes along
  // a contact, and (p, 0) beside (0, p)) are one interface: a vertex where the winding changes is
  // a sheet vertex like its neighbours. Counted as two (the rule before), they pinned thousands
  // of contact vertices, which never moved and left slivers and kinks in the contacts.
  const SurfaceRoles topology = surface_roles(surface, InterfaceSides::either_way);
  const std::vector<Vec3f> original = mesh.positions;
  const Vec3f* o = original.data();
  const Vec3d centre = box_centre(mesh.positions);

  FilterRun run = run_filter(triangles, o, nv, options, iterations, progress, &topology.smooth);
  const F4* counts = run.counts();
  // Smoothed positions relative to the centre (fixed vertices: their own).
  std::vector<Vec3d> smoothed(nv);
  for_each_vertex(nv, [&](size_t i) {
    smoothed[i] = counts[i][3] > 0 ? run.gain * (to_d(o[i]) - centre) + xyz_d(run.d[i])
                                   : to_d(o[i]) - centre;
  });
  // The filter's zero buffer serves the restoration's normals (fresh memory costs page faults).
  F4Buffer spare = std::move(run.own_scratch && run.own_scratch->data() == run.scratch
                                 ? *run.own_scratch
                                 : *run.own_d);
  run = FilterRun{};
  mesh.normals.clear();

  std::vector<Restoration> restore(surface.part_count + 1);
  // The parts the collapse guard looks at: all but those the restoration gave their volume back.
  std::vector<char> check(surface.part_count + 1, 1);
  check[0] = 0;
  // Unit normals of the vertices the restoration moves (zero for the others, which then count as
  // fixed in every part's cubic), in the spare buffer.
  F4* a = spare.data();
  auto normal = [&](uint32_t i) { return xyz_d(a[i]); };
  if (options.preserve_volume) {
    // A free vertex's triangles separate its part from the background wound either way, so each
    // triangle's area vector is turned to point out of its part (the others' normals are unused).
    auto at = [&](uint32_t i) {
      const Vec3d p = smoothed[i];
      return F4{float(p.x), float(p.y), float(p.z), 0.0f};
    };
    // The background inside: its part outside.
    add_area_vectors(triangles, at, a, [&](size_t t) { return surface.sides[t][0] == 0; });
    for_each_vertex(nv, [&](size_t i) {
      a[i] = topology.free_material[i] != 0 ? unit_or(a[i], F4{}) : F4{};
    });
    const std::vector<VolumeCubic> k = material_sums<VolumeCubic>(
        surface.sides.size(), surface.part_count + 1, [&](size_t t, auto&& of) {
          const uint32_t* x = &idx[3 * t];
          const auto [inside, outside] = surface.sides[t];
          auto add = [&](uint32_t m, uint32_t p, uint32_t q, uint32_t r) {
            add_triangle_cubic(of(m), to_d(o[p]) - centre, to_d(o[q]) - centre,
                               to_d(o[r]) - centre, smoothed[p], smoothed[q], smoothed[r],
                               normal(p), normal(q), normal(r));
          };
          add(inside, x[0], x[1], x[2]);
          if (outside != 0) add(outside, x[0], x[2], x[1]);  // the other side, turned around
        });
    for (size_t m = 1; m < k.size(); ++m) {
      restore[m] = solve_restoration(k[m]);
      const double restored = k[m].at(restore[m].delta);
      check[m] = restore[m].keep_original || !(restored >= 2 * kCollapsedVolume * k[m].original);
    }
  }
  for_each_vertex(nv, [&](size_t i) {
    const uint32_t m = topology.free_material[i];
    if (m != 0 && restore[m].keep_original) return;  // a speck: its background vertices as they were
    Vec3d p = centre + smoothed[i];
    if (m != 0 && restore[m].delta != 0) p = p + restore[m].delta * normal(uint32_t(i));
    mesh.positions[i] = to_float(p);
  });
  repair_folds(mesh, original, topology.smooth.role, surface.fold_reach);
  restore_collapsed_parts(surface, original, check);
}

}  // namespace segmesh
