// `segmesh render` end to end, headless (EGL with Mesa's llvmpipe in CI): a volume or a mesh file in,
// a PNG of the requested size out, with the options changing what the pixels show; bad requests
// and a machine without OpenGL give one line, exit code 2 and no file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "support/pictures.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using Png = test::DecodedPng;  // RGB
using test::read_png;
using test::run_segmesh;
constexpr auto q = test::shell_quoted;
constexpr auto red = test::red_dominant;
constexpr auto blue = test::blue_dominant;
constexpr auto green = test::green_dominant;

int count(const Png& png, bool (*pred)(const uint8_t*)) {
  int n = 0;
  for (size_t i = 0; i < png.size(); ++i) n += pred(png.at(i));
  return n;
}

double mean_luminance(const Png& png) {
  double sum = 0;
  for (size_t i = 0; i < png.size(); ++i) {
    sum += test::luminance(png.at(i));
  }
  return sum / double(std::max<size_t>(png.size(), 1));
}

// The phantom at 256 x 256 x 102 voxels of 0.394 x 0.394 x 4 mm, in the test's own folder.
fs::path phantom(const fs::path& dir) {
  const fs::path p = dir / "phantom.nii.gz";
  const auto r = run_segmesh("phantom -o " + q(p) + " --size 256,256,102 --spacing 0.394,0.394,4 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return p;
}

TEST(RenderCli, VolumeToPngOfTheRequestedSizeWithTheImplantRedUnlessHidden) {
  const fs::path dir = test::scratch_dir("cli_render_volume");
  const fs::path input = phantom(dir);
  const auto r = run_segmesh("render " + q(input) + " -o " + q(dir / "view.png") +
                             " --view anterior --size 160,320");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote"), std::string::npos) << r.out;
  const Png view = read_png(dir / "view.png");
  EXPECT_EQ(view.width, 160);
  EXPECT_EQ(view.height, 320);
  const int red_pixels = count(view, red);
  EXPECT_GT(red_pixels, 100);

  const auto hidden = run_segmesh("render " + q(input) + " -o " + q(dir / "hidden.png") +
                                  " --view anterior --size 160,320 --hide implant --quiet");
  ASSERT_EQ(hidden.exit_code, 0) << hidden.err;
  EXPECT_TRUE(hidden.out.empty()) << hidden.out;
  EXPECT_EQ(count(read_png(dir / "hidden.png"), red), 0);
  // By part name: the plate alone (the largest implant part, label2_1) hidden leaves the screws.
  const auto plate = run_segmesh("render " + q(input) + " -o " + q(dir / "no_plate.png") +
                                 " --view anterior --size 160,320 --hide label2_1 --quiet");
  ASSERT_EQ(plate.exit_code, 0) << plate.err;
  const int screws_only = count(read_png(dir / "no_plate.png"), red);
  EXPECT_GT(screws_only, 0);
  EXPECT_LT(screws_only, red_pixels);
  // Framing the implant: a close-up, so the implant covers far more of the picture.
  const auto close = run_segmesh("render " + q(input) + " -o " + q(dir / "close.png") +
                                 " --view anterior --size 160,320 --fit implant --quiet");
  ASSERT_EQ(close.exit_code, 0) << close.err;
  EXPECT_GT(count(read_png(dir / "close.png"), red), 4 * red_pixels);
  EXPECT_TRUE(test::folder_holds_only(
      dir, {"phantom.nii.gz", "view.png", "hidden.png", "no_plate.png", "close.png"}));
}

// render takes the decimation options of `mesh` (the one options layer): the implant decimated to
// a budget is drawn with at most that many triangles, and is still there in red.
TEST(RenderCli, DrawsTheSceneDecimatedToATriangleBudget) {
  const fs::path dir = test::scratch_dir("cli_render_decimated");
  const fs::path input = phantom(dir);
  const auto r = run_segmesh("render " + q(input) + " -o " + q(dir / "implant.png") +
                             " --view anterior --size 160,320 --labels 2 --max-triangles 5000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const size_t at = r.out.find(" triangles drawn");
  ASSERT_NE(at, std::string::npos) << r.out;
  const size_t from = r.out.rfind(' ', at - 1) + 1;
  const long drawn = std::stol(r.out.substr(from, at - from));
  EXPECT_GT(drawn, 1000);
  EXPECT_LE(drawn, 5000);
  EXPECT_GT(count(read_png(dir / "implant.png"), red), 100);
}

TEST(RenderCli, AmbientOcclusionQualityColoursAndClippingChangeThePicture) {
  const fs::path dir = test::scratch_dir("cli_render_options");
  const fs::path input = phantom(dir);
  const std::string base = "render " + q(input) + " --size 160,320 --quiet ";
  ASSERT_EQ(run_segmesh(base + "-o " + q(dir / "ao.png")).exit_code, 0);
  ASSERT_EQ(run_segmesh(base + "-o " + q(dir / "no_ao.png") + " --ao off").exit_code, 0);
  const double with = mean_luminance(read_png(dir / "ao.png"));
  const double without = mean_luminance(read_png(dir / "no_ao.png"));
  EXPECT_LT(with, without);

  // Quality colours on raw Marching Cubes: needles on the 4 mm slices (blue), good triangles on
  // the axial caps (green).
  const auto r = run_segmesh(base + "-o " + q(dir / "quality.png") + " --color quality --smooth none");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Png quality = read_png(dir / "quality.png");
  EXPECT_GT(count(quality, blue), 200);
  EXPECT_GT(count(quality, green), 20);
  EXPECT_EQ(count(read_png(dir / "ao.png"), blue) + count(read_png(dir / "ao.png"), green), 0);

  // Seen from behind with the plate hidden, only the screws' ends stick out of the tibia; a cut
  // through the tibia's axis keeping its anterior half (normal -y) shows the shafts inside.
  ASSERT_EQ(run_segmesh(base + "-o " + q(dir / "back.png") + " --view posterior --hide label2_1").exit_code, 0);
  ASSERT_EQ(run_segmesh(base + "-o " + q(dir / "cut.png") + " --view posterior --hide label2_1" +
                        " --clip 12,-8,0,0,-1,0").exit_code, 0);
  EXPECT_GT(count(read_png(dir / "cut.png"), red), count(read_png(dir / "back.png"), red) + 30);
}

TEST(RenderCli, RendersMeshAndSceneFiles) {
  const fs::path dir = test::scratch_dir("cli_render_mesh");
  const fs::path input = phantom(dir);
  for (const char* name : {"scene.glb", "scene.stl"}) {
    ASSERT_EQ(run_segmesh("mesh " + q(input) + " -o " + q(dir / name) + " --quiet").exit_code, 0);
    const fs::path png = dir / (std::string(name) + ".png");
    const auto r = run_segmesh("render " + q(dir / name) + " -o " + q(png) + " --size 120,200 --view left");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("read"), std::string::npos) << r.out;
    const Png picture = read_png(png);
    EXPECT_EQ(picture.width, 120);
    EXPECT_EQ(picture.height, 200);
    // The glTF scene keeps the materials (a red implant); STL has no materials (all grey).
    if (std::string(name) == "scene.glb") {
      EXPECT_GT(count(picture, red), 20) << name;
    }
  }
}

TEST(RenderCli, BadRequestsAreOneLineErrorsAndWriteNothing) {
  const fs::path dir = test::scratch_dir("cli_render_errors");
  const fs::path input = phantom(dir);
  const std::string out = " -o " + q(dir / "x.png");
  const std::pair<std::string, std::string> cases[] = {
      {"render " + q(input) + out + " --view front", "--view must be"},
      {"render " + q(input) + out + " --size 100x100", "--size expects"},
      {"render " + q(input) + out + " --size 0,10", "--size expects"},
      {"render " + q(input) + " -o " + q(dir / "x.jpg"), "PNG"},
      {"render " + q(input) + out + " --color rainbow", "--color must be"},
      {"render " + q(input) + out + " --ao maybe", "--ao must be"},
      {"render " + q(input) + out + " --ao-radius -1", "--ao-radius must be"},
      {"render " + q(input) + out + " --clip 1,2,3,4,5", "--clip expects"},
      {"render " + q(input) + out + " --clip 1,2,3,0,0,0", "must not be zero"},
      {"render " + q(input) + out + " --hide femur", "no part named \"femur\""},
      {"render " + q(input) + out + " --fit femur", "--fit: no part named \"femur\""},
      {"render " + q(input) + out + " --zoom 0", "--zoom must be"},
      {"render " + q(input) + out + " --method xx", "--method must be mc or dc"},
      {"render " + q(input) + " -o " + q(dir / "missing" / "x.png"), "does not exist"},
      {"render " + q(dir / "absent.nii.gz") + out, "absent.nii.gz"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = run_segmesh(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("segmesh: error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_TRUE(test::folder_holds_only(dir, {"phantom.nii.gz"}));
}

TEST(RenderCli, NoOpenGLIsAClearErrorBeforeAnyWork) {
  const fs::path dir = test::scratch_dir("cli_render_no_gl");
  const fs::path input = phantom(dir);
  // libglvnd finds no EGL driver: as on a machine without Mesa.
  const auto r = test::run_segmesh_with_env("__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json",
                                            "render " + q(input) + " -o " + q(dir / "x.png"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("segmesh: error: cannot create an OpenGL 3.3 context"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("libegl-mesa0"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_TRUE(test::folder_holds_only(dir, {"phantom.nii.gz"}));
  // The study goes on without pictures and says so.
  const auto study = test::run_segmesh_with_env(
      "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json",
      "study " + q(input) + " -o " + q(dir / "study") + " --labels 2 --quiet");
  EXPECT_EQ(study.exit_code, 0) << study.err;
  EXPECT_NE(study.err.find("study without pictures"), std::string::npos) << study.err;
  EXPECT_TRUE(fs::exists(dir / "study" / "study.md"));
  EXPECT_FALSE(fs::exists(dir / "study" / "mc.png"));
}

}  // namespace
}  // namespace segmesh
