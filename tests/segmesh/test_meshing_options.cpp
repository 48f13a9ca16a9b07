// The options layer: defaults resolved once (smoothing iterations per method), every option by
// its command-line name (text round trip, parse errors), and range checks naming the option.
#include "segmesh/meshing_options.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "segmesh/error.hpp"

namespace segmesh {
namespace {

std::string error_of(const MeshingOptions& o) {
  try {
    resolve_meshing_options(o);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(MeshingOptions, DefaultsResolveToWhatSegmeshMeshRuns) {
  const MeshingOptions o = resolve_meshing_options({});
  EXPECT_EQ(o.method, Method::marching_cubes);
  EXPECT_EQ(o.connectivity, 26);
  EXPECT_EQ(o.normals, NormalMethod::central);
  EXPECT_EQ(o.dc_svd_eps, 0.5);
  EXPECT_EQ(o.smooth.method, SmoothMethod::sinc);
  EXPECT_EQ(o.smooth.iterations, 20);
  EXPECT_EQ(o.smooth.pass_band, 0.01);
  EXPECT_TRUE(o.smooth.sinc_unit_gain);
  EXPECT_TRUE(o.smooth.preserve_volume);
  EXPECT_EQ(o.volume_sigma_mm, 0);
}

TEST(MeshingOptions, EachSmoothingMethodGetsItsOwnIterationsUnlessGiven) {
  auto resolved = [](SmoothMethod m, int iterations) {
    MeshingOptions o;
    o.smooth.method = m;
    o.smooth.iterations = iterations;
    return resolve_meshing_options(o).smooth.iterations;
  };
  EXPECT_EQ(resolved(SmoothMethod::laplacian, 0), 2);
  EXPECT_EQ(resolved(SmoothMethod::hc, 0), 2);
  EXPECT_EQ(resolved(SmoothMethod::taubin, 0), 20);
  EXPECT_EQ(resolved(SmoothMethod::sinc, 0), 20);
  EXPECT_EQ(resolved(SmoothMethod::none, 0), 0);
  EXPECT_EQ(resolved(SmoothMethod::hc, 7), 7);
  for (SmoothMethod m : {SmoothMethod::laplacian, SmoothMethod::hc, SmoothMethod::taubin,
                         SmoothMethod::sinc}) {
    EXPECT_EQ(resolved(m, 0), default_smooth_iterations(m));
  }
}

TEST(MeshingOptions, ResolvingTwiceChangesNothing) {
  MeshingOptions o;
  o.smooth.method = SmoothMethod::taubin;
  o.labels = {3, 1};
  const MeshingOptions once = resolve_meshing_options(o);
  const MeshingOptions twice = resolve_meshing_options(once);
  EXPECT_EQ(twice.smooth.iterations, once.smooth.iterations);
  EXPECT_EQ(twice.labels, once.labels);
}

TEST(MeshingOptions, OutOfRangeValuesNameTheirOption) {
  auto with = [](auto change) {
    MeshingOptions o;
    change(o);
    return error_of(o);
  };
  EXPECT_EQ(with([](MeshingOptions& o) { o.connectivity = 7; }),
            "--connectivity must be 6, 18 or 26 (got 7)");
  EXPECT_EQ(with([](MeshingOptions& o) { o.smooth.alpha = 2; }),
            "--alpha must be between 0 and 1 (got 2)");
  EXPECT_EQ(with([](MeshingOptions& o) { o.smooth.iterations = -1; }).rfind("--iterations", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.smooth.pass_band = 0; }).rfind("--pass-band", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.smooth.beta = -0.1; }).rfind("--beta", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.volume_sigma_mm = -1; }).rfind("--presmooth", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.dc_svd_eps = 1.5; }).rfind("--dc-svd-eps", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.dc_tolerance_mm = -2; }).rfind("--dc-tolerance", 0),
            0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.min_voxels = -5; }).rfind("--min-voxels", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) { o.labels = {0}; }).rfind("--labels", 0), 0u);
  EXPECT_EQ(with([](MeshingOptions& o) {
              o.labels = {1};
              o.iso = 3;
            }).rfind("--labels and --iso", 0),
            0u);
}

TEST(MeshingOptions, EverySpecReadsBackWhatItSets) {
  std::set<std::string_view> names;
  const MeshingOptions defaults;
  for (const MeshingOptionSpec& spec : meshing_option_specs()) {
    EXPECT_TRUE(names.insert(spec.name).second) << spec.name << " listed twice";
    EXPECT_EQ(find_meshing_option("--" + std::string(spec.name)), &spec);
    EXPECT_FALSE(spec.help.empty()) << spec.name;
    // The default's text sets the same value.
    MeshingOptions o;
    spec.set(o, spec.get(defaults));
    EXPECT_EQ(spec.get(o), spec.get(defaults)) << spec.name;
  }
  EXPECT_EQ(find_meshing_option("no-such-option"), nullptr);
  // A few values through their names, as the command line and keyword arguments give them.
  MeshingOptions o;
  find_meshing_option("method")->set(o, "dc");
  find_meshing_option("labels")->set(o, "1,2,40");
  find_meshing_option("dc-svd-eps")->set(o, "0.2");
  find_meshing_option("smooth")->set(o, "hc");
  find_meshing_option("preserve-volume")->set(o, "false");
  find_meshing_option("presmooth")->set(o, "+0.75");
  EXPECT_EQ(o.method, Method::dual_contouring);
  EXPECT_EQ(o.labels, (std::vector<int32_t>{1, 2, 40}));
  EXPECT_EQ(o.dc_svd_eps, 0.2);
  EXPECT_EQ(o.smooth.method, SmoothMethod::hc);
  EXPECT_FALSE(o.smooth.preserve_volume);
  EXPECT_EQ(o.volume_sigma_mm, 0.75);
  EXPECT_EQ(find_meshing_option("labels")->get(o), "1,2,40");
  EXPECT_EQ(find_meshing_option("dc-svd-eps")->get(o), "0.2");
}

TEST(MeshingOptions, TextThatDoesNotParseNamesTheOption) {
  auto message = [](std::string_view name, std::string_view text) {
    MeshingOptions o;
    try {
      find_meshing_option(name)->set(o, text);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message("connectivity", "x"), "--connectivity expects a whole number (got \"x\")");
  EXPECT_EQ(message("connectivity", "26.5"),
            "--connectivity expects a whole number (got \"26.5\")");
  EXPECT_EQ(message("iso", "abc"), "--iso expects a number (got \"abc\")");
  EXPECT_EQ(message("method", "mcubes"), "--method must be mc or dc (got \"mcubes\")");
  EXPECT_EQ(message("labels", "1,,x"), "--labels expects whole numbers like 1,2 (got \"1,,x\")");
  EXPECT_EQ(message("unit-gain", "maybe"), "--unit-gain expects true or false (got \"maybe\")");
  EXPECT_NE(message("smooth", "gauss").find("--smooth must be none"), std::string::npos);
}

}  // namespace
}  // namespace segmesh
