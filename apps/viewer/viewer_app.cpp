#include "viewer_app.hpp"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "segmesh/error.hpp"
#include "segmesh_render/png.hpp"
#include "segmesh_viewer/move_history.hpp"
#include "segmesh_viewer/part_pose.hpp"
#include "segmesh_viewer/view_controls.hpp"

namespace segmesh::viewer_app {

namespace fs = std::filesystem;

// The panel's width in window units.
constexpr float kPanelWidth = 380;
// A press that moves less than this (pixels) before release is a click (selects a part).
constexpr float kClickSlop = 4;

ViewerApp::ViewerApp(GLFWwindow* window, AppOptions options)
    : window_(window), options_(std::move(options)), renderer_(std::make_unique<render::Renderer>()) {
  render::set_view(camera_, options_.view);
  color_ = options_.color;
  set_message(state_, "Open a volume or a mesh: File > Open, drop a file on the window, or give it "
                      "on the command line");
  if (!options_.input.empty()) open_path(options_.input);
  if (!options_.screenshot.empty() && options_.input.empty()) {
    // Nothing to wait for: the first complete frame is the empty window.
    frames_with_scene_ = 0;
  }
}

ViewerApp::~ViewerApp() = default;

void ViewerApp::on_drop(std::vector<std::string> paths) {
  if (paths.empty()) return;
  if (paths.size() > 1) {
    set_message(state_, "dropped " + std::to_string(paths.size()) + " files; opening the first");
  }
  open_path(paths.front());
}

void ViewerApp::open_path(const fs::path& path) {
  if (job_.status().running) {
    set_message(state_, "still working on the last request; wait for it or press Cancel", true);
    show_error_ = true;
    return;
  }
  try {
    viewer::LoadRequest request{path, nullptr, viewer::meshing_request(meshing_)};
    if (job_.start(std::move(request))) {
      set_message(state_, "opening " + path.string() + " ...");
    }
  } catch (const Error& e) {
    set_message(state_, e.what(), true);
    show_error_ = true;
  }
}

void ViewerApp::create_mesh() {
  if (!state_.image || job_.status().running) return;
  try {
    viewer::LoadRequest request{{}, state_.image, viewer::meshing_request(meshing_)};
    if (job_.start(std::move(request))) set_message(state_, "meshing " + state_.image->path + " ...");
  } catch (const Error& e) {
    set_message(state_, e.what(), true);
    show_error_ = true;
  }
}

void ViewerApp::collect_job() {
  std::optional<viewer::LoadOutcome> outcome = job_.take_outcome();
  if (!outcome) return;
  const bool loaded = outcome->kind == viewer::LoadOutcome::Kind::loaded;
  const bool failed = outcome->kind == viewer::LoadOutcome::Kind::failed;
  if (failed && !options_.screenshot.empty()) {
    std::fprintf(stderr, "segmesh-viewer: error: %s\n", outcome->message.c_str());
    exit_code_ = 2;
    return;
  }
  if (loaded) field_part_ = -1;  // an edit in progress belonged to the old scene
  finish_load(state_, std::move(*outcome));
  if (failed) show_error_ = true;
  if (loaded) {
    frames_with_scene_ = 0;
    glfwSetWindowTitle(window_, ("segmesh-viewer - " + fs::path(state_.source).filename().string()).c_str());
    if (fit_on_load_) {
      const ViewRect view = view_rect();
      if (first_scene_) render::set_view(camera_, options_.view);
      viewer::fit_scene(camera_, state_.scene, double(view.width) / view.height);
      first_scene_ = false;
    }
  }
}

ViewerApp::ViewRect ViewerApp::view_rect() const {
  int win_w = 1, win_h = 1, fb_w = 1, fb_h = 1;
  glfwGetWindowSize(window_, &win_w, &win_h);
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  const float sx = win_w > 0 ? float(fb_w) / win_w : 1;
  ViewRect r;
  r.win_x = std::min(kPanelWidth, float(win_w) - 1);
  r.win_y = 0;
  r.win_w = std::max(1.0f, float(win_w) - r.win_x);
  r.win_h = std::max(1.0f, float(win_h));
  r.x = int(std::lround(r.win_x * sx));
  r.y = 0;
  r.width = std::max(1, fb_w - r.x);
  r.height = std::max(1, fb_h);
  return r;
}

render::RenderOptions ViewerApp::render_options() const {
  render::RenderOptions o;
  o.color = color_;
  o.ambient_occlusion = ambient_occlusion_;
  o.ao_radius_mm = ao_radius_mm_;
  o.clip = viewer::clip_plane(clip_, state_.scene);
  o.opacity = viewer::render_opacity(state_);
  o.selected = state_.selected;
  o.supersample = 1;
  return o;
}

void ViewerApp::handle_view_input(const ViewRect& view) {
  ImGuiIO& io = ImGui::GetIO();
  const float mx = io.MousePos.x - view.win_x, my = io.MousePos.y - view.win_y;
  const bool inside = mx >= 0 && my >= 0 && mx < view.win_w && my < view.win_h;
  const float scale = float(view.width) / view.win_w;  // framebuffer pixels per window unit

  if (drag_ == Drag::none && !io.WantCaptureMouse && inside) {
    for (int button = 0; button < 3; ++button) {
      if (!ImGui::IsMouseClicked(button)) continue;
      drag_button_ = button;
      press_x_ = mx;
      press_y_ = my;
      drag_ = Drag::pending;
      break;
    }
    if (io.MouseWheel != 0) viewer::wheel_zoom(camera_, io.MouseWheel);
  }
  if (drag_ == Drag::none) return;

  const float dx = io.MouseDelta.x * scale, dy = io.MouseDelta.y * scale;
  if (drag_ == Drag::pending &&
      std::hypot(mx - press_x_, my - press_y_) > kClickSlop) {
    if (drag_button_ == 0 && io.KeyCtrl && state_.selected >= 0) {
      drag_ = Drag::move;
      drag_before_ = state_.views[state_.selected].pose;
    } else {
      drag_ = drag_button_ == 0 ? Drag::orbit : Drag::pan;
    }
  }
  switch (drag_) {
    case Drag::orbit: viewer::drag_orbit(camera_, dx, dy); break;
    case Drag::pan: render::pan(camera_, dx, dy, view.height); break;
    case Drag::move: {
      const size_t i = size_t(state_.selected);
      viewer::PartPose pose = state_.views[i].pose;
      pose.translation_mm = pose.translation_mm +
          viewer::drag_translation(camera_, view.height, dx, dy, viewer::moved_pivot(state_.views[i]));
      viewer::preview_pose(state_, i, pose);
      break;
    }
    default: break;
  }
  if (!ImGui::IsMouseDown(drag_button_)) {
    if (drag_ == Drag::pending && drag_button_ == 0 && !state_.scene.parts.empty()) {
      // A click: select the part under the cursor (or nothing).
      const int px = int(press_x_ * scale), py = int(press_y_ * scale);
      const std::optional<size_t> hit =
          renderer_->pick(state_.scene, camera_, render_options(), view.width, view.height, px, py);
      viewer::select_part(state_, hit ? int(*hit) : -1);
      if (hit) set_message(state_, "selected " + state_.scene.parts[*hit].name +
                                       " (Ctrl + drag moves it)");
    }
    if (drag_ == Drag::move && state_.selected >= 0) {
      viewer::commit_move(state_, size_t(state_.selected), drag_before_);
    }
    drag_ = Drag::none;
    drag_button_ = -1;
  }
}

void ViewerApp::on_key(int key, int action, int mods) {
  if (action == GLFW_PRESS || action == GLFW_REPEAT) keys_.push_back({key, mods});
}

void ViewerApp::handle_keys(const ViewRect& view) {
  std::vector<KeyPress> keys;
  keys.swap(keys_);
  ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard || ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId)) return;
  const double aspect = double(view.width) / view.height;
  for (const KeyPress& k : keys) {
    const bool ctrl = (k.mods & GLFW_MOD_CONTROL) != 0, shift = (k.mods & GLFW_MOD_SHIFT) != 0;
    switch (k.key) {
      case GLFW_KEY_LEFT: viewer::apply_view_key(camera_, viewer::ViewKey::left); break;
      case GLFW_KEY_RIGHT: viewer::apply_view_key(camera_, viewer::ViewKey::right); break;
      case GLFW_KEY_UP: viewer::apply_view_key(camera_, viewer::ViewKey::up); break;
      case GLFW_KEY_DOWN: viewer::apply_view_key(camera_, viewer::ViewKey::down); break;
      case GLFW_KEY_ESCAPE: viewer::select_part(state_, -1); break;
      case GLFW_KEY_Z:
        if (ctrl && shift) viewer::redo(state_);
        else if (ctrl) viewer::undo(state_);
        break;
      case GLFW_KEY_Y:
        if (ctrl) viewer::redo(state_);
        break;
      default: break;
    }
  }
  // Characters follow the keyboard layout ('+' is Shift+= on some, a key of its own on others).
  for (ImWchar c : io.InputQueueCharacters) {
    switch (c) {
      case '+': case '=': viewer::apply_view_key(camera_, viewer::ViewKey::zoom_in); break;
      case '-': case '_': viewer::apply_view_key(camera_, viewer::ViewKey::zoom_out); break;
      case 'f': case 'F': viewer::fit_scene(camera_, state_.scene, aspect); break;
      case '1': viewer::show_standard_view(camera_, state_.scene, render::StandardView::anterior, aspect); break;
      case '2': viewer::show_standard_view(camera_, state_.scene, render::StandardView::posterior, aspect); break;
      case '3': viewer::show_standard_view(camera_, state_.scene, render::StandardView::left, aspect); break;
      case '4': viewer::show_standard_view(camera_, state_.scene, render::StandardView::right, aspect); break;
      case '5': viewer::show_standard_view(camera_, state_.scene, render::StandardView::superior, aspect); break;
      case '6': viewer::show_standard_view(camera_, state_.scene, render::StandardView::inferior, aspect); break;
      case '0': viewer::show_standard_view(camera_, state_.scene, render::StandardView::iso, aspect); break;
      case 'h': case 'H':
        if (state_.selected >= 0) viewer::set_visible(state_, size_t(state_.selected), false);
        break;
      default: break;
    }
  }
}

void ViewerApp::frame() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();

  collect_job();
  const ImGuiIO& io = ImGui::GetIO();
  const bool input = io.MouseDelta.x != 0 || io.MouseDelta.y != 0 || io.MouseWheel != 0 ||
                     !io.InputQueueCharacters.empty() || !keys_.empty() ||
                     ImGui::IsAnyMouseDown() || ImGui::IsMouseReleased(0) || ImGui::IsMouseReleased(1);
  // A running job keeps frames coming (progress), and a few more after it so its outcome is
  // collected and drawn.
  busy_frames_ = input || job_.status().running ? 3 : std::max(0, busy_frames_ - 1);
  const ViewRect view = view_rect();
  handle_view_input(view);
  handle_keys(view);

  draw_panel(view);
  // A field edit ends when no widget is active any more: record it as one step.
  if (field_part_ >= 0 && !ImGui::IsAnyItemActive()) {
    viewer::commit_move(state_, size_t(field_part_), field_before_);
    field_part_ = -1;
  }
  draw_status(view);
  if (color_ == render::ColorMode::quality && !state_.scene.parts.empty()) draw_quality_legend(view);
  handle_dialog();
  draw_error_modal();
  ImGui::Render();

  int fb_w = 1, fb_h = 1;
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  glViewport(0, 0, fb_w, fb_h);
  glClearColor(0.12f, 0.13f, 0.15f, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  if (!state_.scene.parts.empty()) {
    // OpenGL viewports start at the lower left; the view fills the window's height.
    renderer_->draw(state_.scene, camera_, render_options(),
                    render::Viewport{view.x, fb_h - view.y - view.height, view.width, view.height});
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

  const bool job_running = job_.status().running;
  if (!state_.scene.parts.empty() && !job_running) ++frames_with_scene_;
  // --screenshot: the first complete frame — the scene loaded (or the load over), and the UI laid
  // out (Dear ImGui sizes new windows during their first frame and shows them from the second).
  const bool input_done = options_.input.empty() || !state_.source.empty();
  if (!options_.screenshot.empty() && exit_code_ < 0 && !job_running && input_done &&
      (frames_with_scene_ >= 2 || (options_.input.empty() && ImGui::GetFrameCount() >= 3))) {
    screenshot_request_ = options_.screenshot;
  }
  if (pending_screenshot_ && --screenshot_countdown_ <= 0) {
    screenshot_request_ = std::move(pending_screenshot_);
    pending_screenshot_.reset();
  }
  if (screenshot_request_) {
    const fs::path file = *screenshot_request_;
    screenshot_request_.reset();
    try {
      glReadBuffer(GL_BACK);
      render::write_png(render::read_framebuffer(render::Viewport{0, 0, fb_w, fb_h}), file);
      set_message(state_, "wrote " + file.string());
      if (!options_.screenshot.empty()) exit_code_ = 0;
    } catch (const Error& e) {
      if (!options_.screenshot.empty()) {
        std::fprintf(stderr, "segmesh-viewer: error: %s\n", e.what());
        exit_code_ = 2;
      } else {
        set_message(state_, e.what(), true);
        show_error_ = true;
      }
    }
  }
  glfwSwapBuffers(window_);
}

int ViewerApp::run() {
  while (exit_code_ < 0) {
    if (glfwWindowShouldClose(window_)) {
      if (!options_.screenshot.empty()) {
        std::fprintf(stderr, "segmesh-viewer: error: the window was closed before the screenshot\n");
        return 1;
      }
      break;
    }
    // Busy (a job, a drag, input settling, a screenshot to take): keep drawing. Idle: draw
    // nothing until an event arrives (the GPU is not kept busy by a picture that does not change).
    if (job_.status().running || drag_ != Drag::none || busy_frames_ > 0 ||
        pending_screenshot_ || !options_.screenshot.empty()) {
      glfwPollEvents();
    } else {
      glfwWaitEvents();
    }
    frame();
  }
  if (job_.status().running) job_.cancel();
  return exit_code_ < 0 ? 0 : exit_code_;
}

}  // namespace segmesh::viewer_app
