// segmesh-viewer [INPUT] [--screenshot out.png] [--size W,H] [--view V] [--color C]: the planning
// viewer. Opens INPUT (a volume, meshed with the panel's settings, or a mesh or scene file) when
// given. With --screenshot it renders the first complete frame (the scene and the UI), saves it as
// PNG and exits: 0 when written, 2 with one line on stderr when the input cannot be opened or the
// picture not written.
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <sstream>
#include <string>

#include "segmesh/error.hpp"
#include "viewer_app.hpp"

namespace {

namespace fs = std::filesystem;
using segmesh::Error;

std::string glfw_error_text() {
  const char* text = nullptr;
  glfwGetError(&text);
  return text ? text : "unknown GLFW error";
}

// "W,H" with both in 320..16384.
std::pair<int, int> parse_size(const std::string& text) {
  std::istringstream in(text);
  long w = 0, h = 0;
  char comma = 0;
  if (!(in >> w >> comma >> h) || comma != ',' || in.peek() != std::char_traits<char>::eof() || w < 320 ||
      h < 240 || w > 16384 || h > 16384) {
    throw Error("--size expects the window's width and height like 1280,800 (at least 320,240; got \"" +
                text + "\")");
  }
  return {int(w), int(h)};
}

void check_screenshot_path(const std::string& path) {
  const fs::path p(path);
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw Error(path + ": the screenshot is written as PNG; name it *.png");
  const fs::path folder = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw Error(path + ": the folder " + folder.string() + " does not exist");
}

int run(const segmesh::viewer_app::AppOptions& options, int width, int height) {
  glfwSetErrorCallback(nullptr);
  if (!glfwInit()) {
    throw Error("cannot open a window: " + glfw_error_text() +
                " (no display? run it in a desktop session, or headless as xvfb-run -a segmesh-viewer ...)");
  }
  struct Terminate {
    ~Terminate() { glfwTerminate(); }
  } terminate;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* window = glfwCreateWindow(width, height, "segmesh-viewer", nullptr, nullptr);
  if (!window) {
    throw Error("cannot create a window with an OpenGL 3.3 core context: " + glfw_error_text() +
                " (install Mesa's OpenGL drivers: libgl1-mesa-dri, libglx-mesa0)");
  }
  struct Destroy {
    GLFWwindow* w;
    ~Destroy() { glfwDestroyWindow(w); }
  } destroy{window};
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  int code = 0;
  {
    segmesh::viewer_app::ViewerApp app(window, options);
    glfwSetWindowUserPointer(window, &app);
    // Set after Dear ImGui's backend installed its callbacks, so call its key callback first.
    glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int scancode, int action, int mods) {
      ImGui_ImplGlfw_KeyCallback(w, key, scancode, action, mods);
      auto* app = static_cast<segmesh::viewer_app::ViewerApp*>(glfwGetWindowUserPointer(w));
      if (app) app->on_key(key, action, mods);
    });
    glfwSetDropCallback(window, [](GLFWwindow* w, int count, const char** paths) {
      auto* app = static_cast<segmesh::viewer_app::ViewerApp*>(glfwGetWindowUserPointer(w));
      std::vector<std::string> list(paths, paths + count);
      if (app) app->on_drop(std::move(list));
    });
    code = app.run();
    glfwSetWindowUserPointer(window, nullptr);
    glfwSetKeyCallback(window, ImGui_ImplGlfw_KeyCallback);
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli("segmesh-viewer: look at, inspect and plan with the meshes of a segmented CT");
  segmesh::viewer_app::AppOptions options;
  std::string size = "1280,800";
  cli.add_option("input", options.input,
                 "a volume (NIfTI, NRRD, MetaImage, MRC, a DICOM SEG file or a DICOM folder; "
                 "meshed with the panel's settings) or a mesh or scene (.glb, .ply, .stl, .obj)");
  cli.add_option("--screenshot", options.screenshot,
                 "render the first complete frame (scene and UI) to this PNG and exit");
  cli.add_option("--size", size, "the window's width,height")->capture_default_str();
  std::string view = "iso", color = "material";
  cli.add_option("--view", view,
                 "the first view: anterior, posterior, left, right, superior, inferior or iso")
      ->capture_default_str();
  cli.add_option("--color", color, "material or quality (radii ratio, blue 0 to green 1)")
      ->capture_default_str();
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e);
  }
  try {
    const auto [width, height] = parse_size(size);
    const auto standard_view = segmesh::render::parse_view(view);
    if (!standard_view) {
      throw Error("--view must be anterior, posterior, left, right, superior, inferior or iso (got \"" +
                  view + "\")");
    }
    options.view = *standard_view;
    const auto color_mode = segmesh::render::parse_color_mode(color);
    if (!color_mode) throw Error("--color must be material or quality (got \"" + color + "\")");
    options.color = *color_mode;
    if (!options.screenshot.empty()) check_screenshot_path(options.screenshot);
    return run(options, width, height);
  } catch (const Error& e) {
    std::fprintf(stderr, "segmesh-viewer: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "segmesh-viewer: internal error: %s\n", e.what());
    return 1;
  }
}
