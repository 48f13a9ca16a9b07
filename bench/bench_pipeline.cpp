// Google Benchmark cases for the pipeline's steps before smoothing, each through the function the
// pipeline itself calls (pipeline.hpp): reading the volume file, the connected components,
// Marching Cubes and Dual Contouring of every part, and writing the scene as GLB, STL and PLY.
// Each case runs at 1 and 2 threads (the argument), in a oneTBB arena of that size.
//
// Input: a label map file, SEGMESH_BENCH_VOLUME=FILE (e.g. make_big.py's big_seg.nii.gz, or
// ../shared/data/pelvic_fracture/001/001_LI_mask.nii.gz); by default the built-in phantom
// (512 x 512 x 203 at 0.197 x 0.197 x 2 mm) written once as .nii.gz to the temporary folder.
//
//   SEGMESH_BENCH_VOLUME=/tmp/big/big_seg.nii.gz build/bench/segmesh_bench
//     --benchmark_filter='Read|Components|Extract|Write' --benchmark_repetitions=3
#include <benchmark/benchmark.h>
#include <tbb/task_arena.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "segmesh_io/write_volume.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;

const fs::path& volume_path() {
  static const fs::path path = [] {
    const char* given = std::getenv("SEGMESH_BENCH_VOLUME");
    if (given && *given) return fs::path(given);
    const fs::path p = fs::temp_directory_path() / "segmesh_bench_phantom.nii.gz";
    if (!fs::exists(p)) write_volume(make_phantom(), p);
    return p;
  }();
  return path;
}

const Image& image() {
  static const Image img = [] {
    Image i = read_volume(volume_path());
    std::fprintf(stderr, "segmesh_bench volume: %s, %lld x %lld x %lld %s\n",
                 volume_path().c_str(), (long long)i.grid().dims[0], (long long)i.grid().dims[1],
                 (long long)i.grid().dims[2], i.voxel_type.c_str());
    return i;
  }();
  return img;
}

MeshingOptions unsmoothed(Method method) {
  MeshingOptions o;
  o.method = method;
  // Not `none`: that asks Marching Cubes for gradient normals, which the pipeline only computes
  // when nothing smooths afterwards. The smoothing itself is not run here.
  o.smooth = default_smoothing();
  return o;
}

const PipelineParts& parts() {
  static const PipelineParts p = find_parts(image(), unsmoothed(Method::marching_cubes));
  return p;
}

const Scene& mc_scene() {
  static const Scene s = extract_parts(image(), parts(), unsmoothed(Method::marching_cubes));
  return s;
}

void counters(benchmark::State& state, const Scene& scene) {
  size_t triangles = 0;
  for (const Part& p : scene.parts) triangles += p.mesh.triangle_count();
  state.counters["triangles"] = double(triangles);
  state.counters["parts"] = double(scene.parts.size());
}

void BM_ReadVolume(benchmark::State& state) {
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  const auto& d = image().grid().dims;
  for (auto _ : state) {
    Image i;
    arena.execute([&] { i = read_volume(volume_path()); });
    benchmark::DoNotOptimize(i.grid());
  }
  state.counters["Mvoxel/s"] = benchmark::Counter(double(d[0] * d[1] * d[2]) * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Components(benchmark::State& state) {
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  const auto& d = image().grid().dims;
  for (auto _ : state) {
    PipelineParts p;
    arena.execute([&] { p = find_parts(image(), unsmoothed(Method::marching_cubes)); });
    benchmark::DoNotOptimize(p.components.runs.data());
  }
  state.counters["components"] = double(parts().components.components.size());
  state.counters["Mvoxel/s"] = benchmark::Counter(double(d[0] * d[1] * d[2]) * 1e-6,
                                                  benchmark::Counter::kIsIterationInvariantRate);
}

void extract_case(benchmark::State& state, Method method) {
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  const MeshingOptions o = unsmoothed(method);
  Scene scene;
  for (auto _ : state) {
    arena.execute([&] { scene = extract_parts(image(), parts(), o); });
    benchmark::DoNotOptimize(scene.parts.data());
    state.PauseTiming();
    scene = Scene{};  // freeing is not timed
    state.ResumeTiming();
  }
  counters(state, method == Method::marching_cubes ? mc_scene()
                                                   : extract_parts(image(), parts(), o));
}

void BM_ExtractMarchingCubes(benchmark::State& state) { extract_case(state, Method::marching_cubes); }
void BM_ExtractDualContouring(benchmark::State& state) { extract_case(state, Method::dual_contouring); }

void write_case(benchmark::State& state, MeshFormat format, const char* extension) {
  tbb::task_arena arena(static_cast<int>(state.range(0)));
  const fs::path out = fs::temp_directory_path() / (std::string("segmesh_bench_scene") + extension);
  for (auto _ : state) {
    arena.execute([&] { write_scene(mc_scene(), out, format); });
  }
  const double bytes = double(fs::file_size(out));
  state.counters["MB"] = bytes * 1e-6;
  state.counters["MB/s"] = benchmark::Counter(bytes * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
  fs::remove(out);
}

void BM_WriteGlb(benchmark::State& state) { write_case(state, MeshFormat::glb, ".glb"); }
void BM_WriteStl(benchmark::State& state) { write_case(state, MeshFormat::stl, ".stl"); }
void BM_WritePly(benchmark::State& state) { write_case(state, MeshFormat::ply, ".ply"); }

#define SEGMESH_THREADS(f) BENCHMARK(f)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()
SEGMESH_THREADS(BM_ReadVolume);
SEGMESH_THREADS(BM_Components);
SEGMESH_THREADS(BM_ExtractMarchingCubes);
SEGMESH_THREADS(BM_ExtractDualContouring);
SEGMESH_THREADS(BM_WriteGlb);
SEGMESH_THREADS(BM_WriteStl);
SEGMESH_THREADS(BM_WritePly);
#undef SEGMESH_THREADS

}  // namespace
}  // namespace segmesh
