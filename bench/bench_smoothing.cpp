// Google Benchmark cases for the steps after extraction: smoothing (each method with the
// pipeline's iteration counts, the default with volume restoration), vertex normals, the
// adjacency they are built on, and the measures the command line computes for every part
// (measure_mesh, triangle_quality, vertex_quality). Each case runs at 1 and 2 threads (the
// argument), in a oneTBB arena of that size.
//
// Input: the largest part of a volume meshed by Marching Cubes without smoothing. By default the
// built-in phantom (512 x 512 x 203 at 0.197 x 0.197 x 2 mm, ~0.45 M vertices in all parts);
// SEGMESH_BENCH_INPUT=FILE takes a label map instead (e.g. make_big.py's big_seg.nii.gz: one
// part of 2.6 M vertices and 5.2 M triangles), or a mesh file (.ply, .stl, .obj, .glb: its
// largest part as is).
//
//   SEGMESH_BENCH_INPUT=/tmp/big/big_seg.nii.gz build/bench/segmesh_bench
//     --benchmark_filter='Smooth|Measure' --benchmark_repetitions=3   (one command line)
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "segmesh/detail/mesh_adjacency.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/smoothing.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh {
namespace {

TriMesh largest_part(const Scene& scene) {
  const Part* best = nullptr;
  for (const Part& p : scene.parts)
    if (!best || p.mesh.triangle_count() > best->mesh.triangle_count()) best = &p;
  return best ? best->mesh : TriMesh{};
}

// The input mesh, built once.
const TriMesh& input_mesh() {
  static const TriMesh mesh = [] {
    MeshingOptions options;
    options.smooth.method = SmoothMethod::none;
    const char* path = std::getenv("SEGMESH_BENCH_INPUT");
    TriMesh m;
    if (!path || !*path) {
      Image image;
      image.path = "phantom";
      image.voxel_type = "uint8";
      image.volume = make_phantom();
      m = largest_part(build_scene(image, options));
    } else {
      const std::string ext = std::filesystem::path(path).extension().string();
      if (ext == ".ply" || ext == ".stl" || ext == ".obj" || ext == ".glb") {
        m = largest_part(read_mesh(path));
      } else {
        m = largest_part(build_scene(read_volume(path), options));
      }
    }
    std::fprintf(stderr, "segmesh_bench input: %s, largest part %zu vertices, %zu triangles\n",
                 path && *path ? path : "phantom", m.positions.size(), m.triangle_count());
    return m;
  }();
  return mesh;
}

void set_counters(benchmark::State& state, const TriMesh& mesh) {
  state.counters["vertices"] = double(mesh.positions.size());
  state.counters["Mvert/s"] = benchmark::Counter(double(mesh.positions.size()) * 1e-6,
                                                 benchmark::Counter::kIsIterationInvariantRate);
}

// Smooths a fresh copy each iteration (the copy is not timed).
void smooth_case(benchmark::State& state, SmoothOptions options) {
  const TriMesh& input = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    state.PauseTiming();
    TriMesh mesh = input;
    state.ResumeTiming();
    arena.execute([&] { smooth_mesh(mesh, options); });
    benchmark::DoNotOptimize(mesh.positions.data());
    state.PauseTiming();
    mesh = TriMesh{};  // freeing is not timed either
    state.ResumeTiming();
  }
  set_counters(state, input);
}

void BM_SmoothLaplacian2(benchmark::State& state) {
  smooth_case(state, {.method = SmoothMethod::laplacian, .iterations = 2, .preserve_volume = false});
}
void BM_SmoothHc2(benchmark::State& state) {
  smooth_case(state, {.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
}
void BM_SmoothHc2Volume(benchmark::State& state) {
  smooth_case(state, {.method = SmoothMethod::hc, .iterations = 2});
}
void BM_SmoothTaubin20(benchmark::State& state) {
  smooth_case(state, {.method = SmoothMethod::taubin, .iterations = 20, .preserve_volume = false});
}
// 3D Slicer's setting: VTK's filter exactly (no unit gain, no volume restoration).
void BM_SmoothSincVtk20(benchmark::State& state) {
  smooth_case(state, {.method = SmoothMethod::sinc, .iterations = 20, .pass_band = 0.01,
                      .sinc_unit_gain = false, .preserve_volume = false});
}
// segmesh's default: unit gain, volume restored.
void BM_SmoothDefault(benchmark::State& state) { smooth_case(state, default_smoothing()); }

void BM_VertexNormals(benchmark::State& state) {
  TriMesh mesh = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    arena.execute([&] { compute_vertex_normals(mesh); });
    benchmark::DoNotOptimize(mesh.normals.data());
  }
  set_counters(state, mesh);
}

// The corner rows and their conversion to fan rings: what every smoothing and normals call
// builds first.
void BM_Adjacency(benchmark::State& state) {
  const TriMesh& mesh = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    arena.execute([&] {
      VertexRows<uint32_t> rows = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
      benchmark::DoNotOptimize(corners_to_rings(mesh.indices, rows));
      benchmark::DoNotOptimize(rows.entries.data());
    });
  }
  set_counters(state, mesh);
}

void BM_MeasureMesh(benchmark::State& state) {
  const TriMesh& mesh = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    MeshMeasures m;
    arena.execute([&] { m = measure_mesh(mesh); });
    benchmark::DoNotOptimize(m);
  }
  set_counters(state, mesh);
}

void BM_TriangleQuality(benchmark::State& state) {
  const TriMesh& mesh = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    QualityStats q;
    arena.execute([&] { q = triangle_quality(mesh); });
    benchmark::DoNotOptimize(q);
  }
  set_counters(state, mesh);
}

void BM_VertexQuality(benchmark::State& state) {
  const TriMesh& mesh = input_mesh();
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    std::vector<float> q;
    arena.execute([&] { q = vertex_quality(mesh); });
    benchmark::DoNotOptimize(q.data());
  }
  set_counters(state, mesh);
}

#define SEGMESH_THREADS(f) BENCHMARK(f)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()
SEGMESH_THREADS(BM_SmoothLaplacian2);
SEGMESH_THREADS(BM_SmoothHc2);
SEGMESH_THREADS(BM_SmoothHc2Volume);
SEGMESH_THREADS(BM_SmoothTaubin20);
SEGMESH_THREADS(BM_SmoothSincVtk20);
SEGMESH_THREADS(BM_SmoothDefault);
SEGMESH_THREADS(BM_VertexNormals);
SEGMESH_THREADS(BM_Adjacency);
SEGMESH_THREADS(BM_MeasureMesh);
SEGMESH_THREADS(BM_TriangleQuality);
SEGMESH_THREADS(BM_VertexQuality);
#undef SEGMESH_THREADS

}  // namespace
}  // namespace segmesh
