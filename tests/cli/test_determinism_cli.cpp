// segmesh mesh writes the same bytes whatever the number of threads: the whole path (components,
// Marching Cubes or Dual Contouring, the default smoothing, writing) for GLB and STL scenes and for
// one file per part.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "cli/cli_run.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using test::run_segmesh;

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

TEST(CliDeterminism, SameBytesForOneTwoAndFourThreads) {
  const fs::path dir = test::scratch_dir("cli_determinism");
  const fs::path phantom = dir / "phantom.nii.gz";
  ASSERT_EQ(run_segmesh("phantom -o " + q(phantom) + " --size 256,256,102 --spacing 0.394,0.394,4").exit_code, 0);
  for (const std::string method : {"mc", "dc"}) {
    for (const std::string out : {"scene.glb", "scene.stl", "parts/"}) {
      std::string first;
      for (int threads : {1, 2, 4}) {
        // The same file name in its own folder per run (an STL header holds the scene's name).
        const fs::path run_dir = dir / (method + std::to_string(threads));
        fs::create_directories(run_dir);
        const fs::path target = run_dir / out;
        const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(target) + " --method " + method +
                                   " --threads " + std::to_string(threads) + " --quiet");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        std::string bytes;
        if (out == "parts/") {
          for (const auto& e : fs::directory_iterator(target)) bytes += e.path().filename().string();
          bytes = std::to_string(bytes.size()) + ":";  // file names first, then their contents
          for (const char* name : {"label1_1.ply", "label2_1.ply", "label2_7.ply"}) {
            ASSERT_TRUE(fs::exists(target / name)) << name;
            bytes += bytes_of(target / name);
          }
        } else {
          bytes = bytes_of(target);
        }
        ASSERT_GT(bytes.size(), 1000u);
        if (threads == 1) {
          first = bytes;
        } else {
          EXPECT_TRUE(bytes == first) << method << " " << out << ": " << threads
                                      << " threads wrote other bytes than 1";
        }
      }
    }
  }
}

}  // namespace
}  // namespace segmesh
