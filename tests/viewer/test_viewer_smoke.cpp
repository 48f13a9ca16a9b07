// segmesh-viewer end to end under Xvfb: `segmesh-viewer INPUT --screenshot out.png` opens the
// input (a volume meshed on the worker thread, or a GLB scene), draws the first complete frame
// with its UI and writes it. The picture must show the scene (many colours, the implant's red in
// the 3D view) and the panel; a bad input gives one line, exit code 2 and no picture.
// Skipped, saying so, when xvfb-run is not installed (scripts/install-deps.sh installs it).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support/pictures.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using Png = test::DecodedPng;  // RGB
using test::read_png;
constexpr auto q = test::shell_quoted;
constexpr auto red = test::red_dominant;

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct ProcessResult {
  int exit_code = -1;
  std::string err;
};

// Runs a shell command with stdout and stderr captured in `dir`.
ProcessResult run(const std::string& command, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const int status = std::system((command + " >" + q(out) + " 2>" + q(err)).c_str());
  ProcessResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = slurp(err);
  return r;
}

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// segmesh-viewer under Xvfb. -noreset: when its last client leaves, Xvfb resets and signals
// xvfb-run again (SIGUSR1), which can interrupt xvfb-run's clean-up: it then exits with 5 and
// leaves the server running. The viewer's own exit code is also taken from inside the session.
ProcessResult viewer(const std::string& args, const fs::path& dir) {
  const fs::path script = dir / "run_viewer.sh", code = dir / "viewer_exit_code.txt";
  std::ofstream(script) << q(SEGMESH_VIEWER_EXE) << " " << args << "\necho $? > " << q(code) << "\n";
  ProcessResult r = run("xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' sh " + q(script), dir);
  std::ifstream in(code);
  if (!(in >> r.exit_code)) r.exit_code = -1;  // the viewer never ran (xvfb-run failed)
  return r;
}

bool bright(const uint8_t* p) { return p[0] > 150 && p[1] > 150 && p[2] > 150; }

struct Counts {
  int red = 0, bright = 0;
  size_t colours = 0;  // distinct colours, quantised to 5 bits per channel
};

// Counts over the columns [x0, x1).
Counts count(const Png& png, int x0, int x1) {
  Counts c;
  std::set<int> colours;
  for (int y = 0; y < png.height; ++y) {
    for (int x = x0; x < x1; ++x) {
      const uint8_t* p = png.at(x, y);
      c.red += red(p);
      c.bright += bright(p);
      colours.insert((p[0] >> 3) << 10 | (p[1] >> 3) << 5 | (p[2] >> 3));
    }
  }
  c.colours = colours.size();
  return c;
}

// The phantom at 256 x 256 x 102 voxels of 0.394 x 0.394 x 4 mm.
fs::path phantom(const fs::path& dir) {
  const fs::path p = dir / "phantom.nii.gz";
  const ProcessResult r = run(q(SEGMESH_EXE) + " phantom -o " + q(p) + " --size 256,256,102 --spacing 0.394,0.394,4 --quiet", dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return p;
}

// The panel is 380 window units wide on the left; the 3D view is the rest.
constexpr int kPanel = 380;

TEST(ViewerSmoke, AVolumeIsMeshedAndTheFirstFrameSaved) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (scripts/install-deps.sh installs xvfb)";
  const fs::path dir = test::scratch_dir("viewer_smoke_volume");
  const fs::path input = phantom(dir), shot = dir / "x.png";
  const ProcessResult r = viewer(q(input) + " --screenshot " + q(shot) + " --size 1024,720", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Png png = read_png(shot);
  ASSERT_EQ(png.width, 1024);
  ASSERT_EQ(png.height, 720);
  const Counts view = count(png, kPanel, png.width);
  const Counts panel = count(png, 0, kPanel);
  EXPECT_GT(view.colours, 50u) << "the 3D view looks blank";
  EXPECT_GT(view.red, 200) << "no red implant pixels in the 3D view";
  EXPECT_GT(view.bright, 200) << "no white bone pixels in the 3D view";
  EXPECT_GT(panel.colours, 5u) << "the panel looks blank";
  EXPECT_GT(panel.bright, 500) << "no panel text";
}

TEST(ViewerSmoke, AGlbSceneOpensToo) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (scripts/install-deps.sh installs xvfb)";
  const fs::path dir = test::scratch_dir("viewer_smoke_glb");
  const fs::path scene = dir / "leg.glb", shot = dir / "leg.png";
  const ProcessResult m = run(q(SEGMESH_EXE) + " mesh " + q(phantom(dir)) + " -o " + q(scene) + " --quiet", dir);
  ASSERT_EQ(m.exit_code, 0) << m.err;
  const ProcessResult r = viewer(q(scene) + " --screenshot " + q(shot) + " --size 800,600", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Png png = read_png(shot);
  ASSERT_EQ(png.width, 800);
  EXPECT_GT(count(png, kPanel, png.width).red, 100);
}

TEST(ViewerSmoke, ABadInputIsOneLineAndNoPicture) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (scripts/install-deps.sh installs xvfb)";
  const fs::path dir = test::scratch_dir("viewer_smoke_bad");
  const fs::path input = dir / "broken.nii.gz", shot = dir / "never.png";
  std::ofstream(input) << "not a volume";
  const ProcessResult r = viewer(q(input) + " --screenshot " + q(shot), dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("segmesh-viewer: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("broken.nii.gz"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(shot));
  // A screenshot that is not a PNG is refused before any window opens.
  const ProcessResult n = run(q(SEGMESH_VIEWER_EXE) + " " + q(input) + " --screenshot " + q(dir / "x.jpg"), dir);
  EXPECT_EQ(n.exit_code, 2);
  EXPECT_NE(n.err.find("PNG"), std::string::npos) << n.err;
}

}  // namespace
}  // namespace segmesh
