// ViewerApp: the planning viewer's window — GLFW for the window and input, Dear ImGui for the
// panels, segmesh_render's Renderer for the 3D view, segmesh_viewer for every piece of state and
// logic (this class only maps widgets and mouse/keys onto those functions).
//
// Layout: a panel on the left (file, meshing, views, display, parts, selected part), the 3D view
// to its right, a status line at the bottom of the view (last message, progress and Cancel while a
// job runs), the quality legend at the top right of the view in quality colours.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "file_dialog.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/renderer.hpp"
#include "segmesh_viewer/clip_settings.hpp"
#include "segmesh_viewer/load_job.hpp"
#include "segmesh_viewer/meshing_settings.hpp"
#include "segmesh_viewer/viewer_state.hpp"

struct GLFWwindow;

namespace segmesh::viewer_app {

struct AppOptions {
  std::string input;       // opened at start when not empty
  std::string screenshot;  // --screenshot: save the first complete frame here and quit
  render::StandardView view = render::StandardView::iso;  // --view: the first scene's view
  render::ColorMode color = render::ColorMode::material;  // --color
};

class ViewerApp {
 public:
  // The window's OpenGL 3.3 core context must be current and ImGui initialised for it.
  ViewerApp(GLFWwindow* window, AppOptions options);
  ~ViewerApp();

  // Runs until the window is closed (0), or in screenshot mode until the picture is written (0)
  // or opening the input failed (2, after printing one line on stderr).
  int run();

  // glfwSetDropCallback forwards here.
  void on_drop(std::vector<std::string> paths);
  // The key callback forwards presses and repeats here (after Dear ImGui's own callback). Keys are
  // queued rather than polled: a press and release within one frame (fast typing, a batch of
  // events) would otherwise be missed.
  void on_key(int key, int action, int mods);

 private:
  struct ViewRect {  // the 3D view, in framebuffer pixels (y down from the top) and window units
    int x = 0, y = 0, width = 1, height = 1;
    float win_x = 0, win_y = 0, win_w = 1, win_h = 1;
  };

  void frame();
  void collect_job();
  void open_path(const std::filesystem::path& path);
  void create_mesh();
  void handle_view_input(const ViewRect& view);
  void handle_keys(const ViewRect& view);
  render::RenderOptions render_options() const;
  ViewRect view_rect() const;

  void draw_panel(const ViewRect& view);
  void draw_file_section();
  void draw_meshing_section();
  void draw_view_section(const ViewRect& view);
  void draw_display_section();
  void draw_parts_section();
  void draw_selection_section();
  void draw_statistics_section();
  void draw_status(const ViewRect& view);
  void draw_quality_legend(const ViewRect& view);
  void draw_error_modal();
  void handle_dialog();

  GLFWwindow* window_;
  AppOptions options_;
  std::unique_ptr<render::Renderer> renderer_;
  viewer::ViewerState state_;
  viewer::LoadJob job_;
  viewer::MeshingSettings meshing_;
  viewer::ClipSettings clip_;
  render::Camera camera_;
  render::ColorMode color_ = render::ColorMode::material;
  bool ambient_occlusion_ = true;
  double ao_radius_mm_ = 0;  // 0: automatic (render::ao_parameters)
  FileDialog dialog_;

  bool fit_on_load_ = true;        // the next loaded scene is framed (iso view the first time)
  bool first_scene_ = true;
  bool show_error_ = false;        // open the error modal
  std::optional<std::filesystem::path> screenshot_request_;  // taken at the end of this frame
  std::optional<std::filesystem::path> pending_screenshot_;  // from the dialog, after it closed
  int screenshot_countdown_ = 0;
  int frames_with_scene_ = 0;      // complete frames drawn since the scene was loaded
  int exit_code_ = -1;             // >= 0: leave the loop with it
  // Frames still to draw without waiting for events: Dear ImGui needs a frame or two after an
  // input to settle (a popup opens the frame after the click that asked for it).
  int busy_frames_ = 0;

  struct KeyPress {
    int key = 0, mods = 0;
  };
  std::vector<KeyPress> keys_;  // since the last frame

  // Mouse interaction in the 3D view.
  enum class Drag { none, pending, orbit, pan, move };
  Drag drag_ = Drag::none;
  int drag_button_ = -1;
  float press_x_ = 0, press_y_ = 0;
  viewer::PartPose drag_before_;
  // Field edits of the selected part (one undo step per edit): the part being edited (-1: none)
  // and its pose before the edit.
  int field_part_ = -1;
  viewer::PartPose field_before_;
};

}  // namespace segmesh::viewer_app
