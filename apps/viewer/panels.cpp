// ViewerApp's Dear ImGui panels: each widget reads the state and calls one segmesh_viewer function.
#include <imgui.h>
#include <imgui_internal.h>  // PushItemFlag: the group checkbox's mixed state

#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>

#include "segmesh/error.hpp"
#include "segmesh/smoothing.hpp"
#include "segmesh_viewer/move_history.hpp"
#include "segmesh_viewer/part_groups.hpp"
#include "segmesh_viewer/part_table.hpp"
#include "segmesh_viewer/save_scene.hpp"
#include "segmesh_viewer/view_controls.hpp"
#include "viewer_app.hpp"

namespace segmesh::viewer_app {

namespace fs = std::filesystem;

namespace {

template <typename Enum, size_t N>
bool enum_combo(const char* label, Enum& value, const std::pair<Enum, const char*> (&items)[N]) {
  const char* current = "";
  for (const auto& [v, name] : items) {
    if (v == value) current = name;
  }
  bool changed = false;
  if (ImGui::BeginCombo(label, current)) {
    for (const auto& [v, name] : items) {
      if (ImGui::Selectable(name, v == value)) {
        value = v;
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  return changed;
}

// "leg.nii.gz" -> "leg": a default name for files saved from the scene.
std::string stem_of(const std::string& source) {
  fs::path name = fs::path(source).filename();
  if (name.extension() == ".gz") name = name.stem();
  const std::string stem = name.stem().string();
  return stem.empty() ? "scene" : stem;
}

}  // namespace

void ViewerApp::draw_panel(const ViewRect& view) {
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(view.win_x, view.win_h), ImGuiCond_Always);
  ImGui::Begin("segmesh-viewer", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  draw_file_section();
  draw_meshing_section();
  draw_view_section(view);
  draw_display_section();
  draw_parts_section();
  draw_selection_section();
  draw_statistics_section();
  ImGui::End();
}

void ViewerApp::draw_file_section() {
  if (!ImGui::CollapsingHeader("File", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::TextWrapped("%s", state_.source.empty() ? "(nothing open)" : state_.source.c_str());
  if (ImGui::Button("Open...")) dialog_.open(FileDialog::Mode::open, "Open a volume or a mesh", "open");
  ImGui::SameLine();
  ImGui::BeginDisabled(state_.scene.parts.empty());
  if (ImGui::Button("Save GLB...")) {
    dialog_.open(FileDialog::Mode::save, "Save the scene as GLB", "glb", stem_of(state_.source) + "_plan.glb");
  }
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Screenshot...")) {
    dialog_.open(FileDialog::Mode::save, "Save a screenshot (PNG)", "png", stem_of(state_.source) + ".png");
  }
}

void ViewerApp::draw_meshing_section() {
  if (!ImGui::CollapsingHeader("Meshing", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const viewer::JobStatus status = job_.status();
  ImGui::BeginDisabled(status.running);
  enum_combo("method", meshing_.method,
             {std::pair{Method::marching_cubes, "Marching Cubes"}, std::pair{Method::dual_contouring, "Dual Contouring"}});
  enum_combo("surfaces", meshing_.surfaces,
             {std::pair{Surfaces::automatic, "automatic"}, std::pair{Surfaces::conforming, "conforming"},
              std::pair{Surfaces::independent, "independent"}});
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("conforming: touching parts share one surface at their contact\n"
                      "independent: every part meshed and smoothed on its own\n"
                      "automatic: conforming with Marching Cubes, independent with Dual Contouring");
  }
  enum_combo("normals", meshing_.normals,
             {std::pair{NormalMethod::central, "central differences"}, std::pair{NormalMethod::sobel, "Sobel"}});
  if (enum_combo("smoothing", meshing_.smooth,
                 {std::pair{SmoothMethod::none, "none"}, std::pair{SmoothMethod::laplacian, "Laplacian"},
                  std::pair{SmoothMethod::hc, "HC"}, std::pair{SmoothMethod::taubin, "Taubin"},
                  std::pair{SmoothMethod::sinc, "windowed sinc"}})) {
    meshing_.iterations = default_smooth_iterations(meshing_.smooth);
  }
  ImGui::BeginDisabled(meshing_.smooth == SmoothMethod::none);
  ImGui::SliderInt("iterations", &meshing_.iterations, 1, 100);
  ImGui::EndDisabled();
  char labels[256];
  std::snprintf(labels, sizeof labels, "%s", meshing_.labels.c_str());
  if (ImGui::InputTextWithHint("labels", "all, or e.g. 1,2", labels, sizeof labels)) meshing_.labels = labels;
  ImGui::InputDouble("decimate error (mm)", &meshing_.decimate_error_mm, 0.05, 0.5, "%.2f");
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("0: no decimation; else the largest distance allowed");
  ImGui::InputInt("max triangles", &meshing_.max_triangles, 1000, 10000);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("0: no budget; else the whole scene's triangle budget");
  ImGui::BeginDisabled(!state_.image);
  if (ImGui::Button("Create mesh")) create_mesh();
  ImGui::EndDisabled();
  if (!state_.image && !status.running) {
    ImGui::SameLine();
    ImGui::TextDisabled("(open a volume first)");
  }
  ImGui::EndDisabled();
  if (!state_.surfaces.empty()) ImGui::TextWrapped("%s", state_.surfaces.c_str());
  if (!state_.scene.parts.empty()) ImGui::Text("%s", viewer::triangle_count_text(state_.scene).c_str());
  if (status.running) {
    char overlay[128];
    std::snprintf(overlay, sizeof overlay, "%s %.0f%%", status.step.c_str(), 100 * status.fraction);
    ImGui::ProgressBar(float(status.fraction), ImVec2(-80, 0), overlay);
    ImGui::SameLine();
    if (ImGui::Button("Cancel##mesh")) job_.cancel();
  }
}

void ViewerApp::draw_view_section(const ViewRect& view) {
  if (!ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const double aspect = double(view.width) / view.height;
  const std::pair<render::StandardView, const char*> views[] = {
      {render::StandardView::anterior, "Anterior"}, {render::StandardView::posterior, "Posterior"},
      {render::StandardView::left, "Left"},         {render::StandardView::right, "Right"},
      {render::StandardView::superior, "Superior"}, {render::StandardView::inferior, "Inferior"},
      {render::StandardView::iso, "Iso"}};
  int n = 0;
  for (const auto& [v, name] : views) {
    if (n++ % 4 != 0) ImGui::SameLine();
    if (ImGui::Button(name)) viewer::show_standard_view(camera_, state_.scene, v, aspect);
  }
  ImGui::SameLine();
  if (ImGui::Button("Fit")) viewer::fit_scene(camera_, state_.scene, aspect);
  ImGui::TextDisabled("drag: orbit, right drag: pan, wheel: zoom");
}

void ViewerApp::draw_display_section() {
  if (!ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) return;
  int mode = color_ == render::ColorMode::material ? 0 : 1;
  ImGui::RadioButton("materials", &mode, 0);
  ImGui::SameLine();
  ImGui::RadioButton("triangle quality", &mode, 1);
  color_ = mode == 0 ? render::ColorMode::material : render::ColorMode::quality;
  ImGui::Checkbox("ambient occlusion (SSAO)", &ambient_occlusion_);
  if (ambient_occlusion_) {
    // The same parameter as `segmesh render --ao-radius`: 0 is the automatic radius.
    ImGui::InputDouble("occlusion radius (mm)", &ao_radius_mm_, 0.5, 2.0, "%.1f");
    if (!(ao_radius_mm_ >= 0)) ao_radius_mm_ = 0;  // negative or not a number: automatic
    ao_radius_mm_ = std::min(ao_radius_mm_, 100.0);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("how far occluders count; 0: automatic (6 %% of the visible parts' "
                        "diagonal, 2 to 10 mm)");
  }
  ImGui::Checkbox("clipping plane", &clip_.enabled);
  if (clip_.enabled) {
    const char* axes[] = {"x (left-right)", "y (front-back)", "z (up-down)"};
    ImGui::Combo("axis", &clip_.axis, axes, 3);
    ImGui::SliderFloat("position", &clip_.position, 0, 1, "%.2f");
    ImGui::Checkbox("keep the other side", &clip_.flip);
  }
}

void ViewerApp::draw_parts_section() {
  if (!ImGui::CollapsingHeader("Parts", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (state_.scene.parts.empty()) {
    ImGui::TextDisabled("(no parts)");
    return;
  }
  const std::vector<viewer::PartGroup> groups = viewer::group_parts_by_label(state_.scene);
  for (const viewer::PartGroup& g : groups) {
    ImGui::PushID(g.label);
    bool all = viewer::group_all_visible(state_.scene, g);
    const bool none = viewer::group_none_visible(state_.scene, g);
    if (!all && !none) ImGui::PushItemFlag(ImGuiItemFlags_MixedValue, true);
    if (ImGui::Checkbox("##group", &all)) {
      for (size_t i : g.parts) viewer::set_visible(state_, i, all);
    }
    if (!all && !none) ImGui::PopItemFlag();
    ImGui::SameLine();
    char title[256];
    const std::string plain = "label" + std::to_string(g.label);  // the name says the label already
    if (g.name == plain) {
      std::snprintf(title, sizeof title, "%s (%s, %zu part%s)", g.name.c_str(),
                    std::string(role_name(g.role)).c_str(), g.parts.size(), g.parts.size() == 1 ? "" : "s");
    } else {
      std::snprintf(title, sizeof title, "%s (label %d, %zu part%s)", g.name.c_str(), g.label,
                    g.parts.size(), g.parts.size() == 1 ? "" : "s");
    }
    if (ImGui::TreeNodeEx("##tree", ImGuiTreeNodeFlags_DefaultOpen, "%s", title)) {
      for (size_t i : g.parts) {
        Part& part = state_.scene.parts[i];
        ImGui::PushID(int(i));
        bool visible = part.visible;
        if (ImGui::Checkbox("##visible", &visible)) viewer::set_visible(state_, i, visible);
        ImGui::SameLine();
        float color[3] = {part.material.base_color.r, part.material.base_color.g, part.material.base_color.b};
        if (ImGui::ColorEdit3("##color", color, ImGuiColorEditFlags_NoInputs | ImGuiColorEditFlags_NoLabel)) {
          viewer::set_color(state_, i, Rgb{color[0], color[1], color[2]});
        }
        ImGui::SameLine();
        ImGui::SetNextItemWidth(70);
        float opacity = state_.views[i].opacity;
        if (ImGui::SliderFloat("##opacity", &opacity, 0, 1, "%.2f")) viewer::set_opacity(state_, i, opacity);
        ImGui::SameLine();
        if (ImGui::Selectable(part.name.c_str(), state_.selected == int(i))) {
          viewer::select_part(state_, state_.selected == int(i) ? -1 : int(i));
        }
        ImGui::PopID();
      }
      ImGui::TreePop();
    }
    ImGui::PopID();
  }
}

void ViewerApp::draw_selection_section() {
  if (!ImGui::CollapsingHeader("Selected part", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::BeginDisabled(!viewer::can_undo(state_));
  if (ImGui::Button("Undo")) viewer::undo(state_);
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(!viewer::can_redo(state_));
  if (ImGui::Button("Redo")) viewer::redo(state_);
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Reset all moves")) viewer::reset_moves(state_);

  if (state_.selected < 0 || size_t(state_.selected) >= state_.scene.parts.size()) {
    ImGui::TextDisabled("click a part in the view or the list");
    return;
  }
  const size_t i = size_t(state_.selected);
  const Part& part = state_.scene.parts[i];
  ImGui::Text("%s  (%s, label %d)", part.name.c_str(), std::string(role_name(part.role)).c_str(), part.label);

  // Translate and rotate fields: one undo step per edit, from the first change until no widget is
  // active any more (the mouse released, or Enter in a typed value).
  viewer::PartPose pose = state_.views[i].pose;
  float t[3] = {float(pose.translation_mm.x), float(pose.translation_mm.y), float(pose.translation_mm.z)};
  float r[3] = {float(pose.rotation_deg.x), float(pose.rotation_deg.y), float(pose.rotation_deg.z)};
  auto field = [&](const char* label, float* v, float speed, Vec3d& out) {
    if (!ImGui::DragFloat3(label, v, speed, 0, 0, "%.1f")) return;
    if (field_part_ != int(i)) {
      field_part_ = int(i);
      field_before_ = state_.views[i].pose;
    }
    out = {v[0], v[1], v[2]};
    viewer::preview_pose(state_, i, pose);
  };
  field("translate mm", t, 0.5f, pose.translation_mm);
  field("rotate deg", r, 0.5f, pose.rotation_deg);
  if (ImGui::Button("Reset part")) viewer::reset_part(state_, i);
  ImGui::SameLine();
  if (ImGui::Button("Hide")) viewer::set_visible(state_, i, false);
  ImGui::TextDisabled("Ctrl + drag in the view moves it");

  if (i < state_.stats.size()) {
    const viewer::PartStats& s = state_.stats[i];
    if (ImGui::BeginTable("stats", 2, ImGuiTableFlags_BordersInnerH)) {
      auto row = [](const char* name, const char* fmt, auto value) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        ImGui::TextUnformatted(name);
        ImGui::TableSetColumnIndex(1);
        ImGui::Text(fmt, value);
      };
      row("vertices", "%lld", (long long)s.vertices);
      row("triangles", "%lld", (long long)s.triangles);
      row("area", "%.1f mm2", s.area_mm2);
      row("volume", "%.1f mm3", s.volume_mm3);
      row("radii ratio min", "%.3f", s.rho_min);
      row("radii ratio mean", "%.3f", s.rho_mean);
      row("closed", "%s", s.closed ? "yes" : "no");
      for (const std::string& contact : viewer::part_table_row(state_.scene, state_.stats, i).contacts) {
        row("contact", "%s", contact.c_str());
      }
      ImGui::EndTable();
    }
  }
}

void ViewerApp::draw_statistics_section() {
  if (!ImGui::CollapsingHeader("Statistics (all parts)")) return;
  const ImGuiTableFlags flags = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV |
                                ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollX;
  if (!ImGui::BeginTable("all_stats", int(viewer::kPartTableColumns.size()), flags)) return;
  for (std::string_view name : viewer::kPartTableColumns) ImGui::TableSetupColumn(std::string(name).c_str());
  ImGui::TableHeadersRow();
  const std::vector<viewer::PartTableRow> rows = viewer::part_table(state_.scene, state_.stats);
  for (size_t i = 0; i < rows.size(); ++i) {
    const viewer::PartTableRow& row = rows[i];
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    if (ImGui::Selectable(row.cells[0].c_str(), state_.selected == int(i), ImGuiSelectableFlags_SpanAllColumns)) {
      viewer::select_part(state_, int(i));
    }
    for (size_t c = 1; c < row.cells.size(); ++c) {
      ImGui::TableSetColumnIndex(int(c));
      ImGui::TextUnformatted(row.cells[c].c_str());
    }
    // One line per contact; a part without contacts leaves the cell empty.
    ImGui::TableSetColumnIndex(int(row.cells.size()));
    for (const std::string& contact : row.contacts) ImGui::TextUnformatted(contact.c_str());
  }
  ImGui::EndTable();
}

void ViewerApp::draw_status(const ViewRect& view) {
  const float height = ImGui::GetFrameHeightWithSpacing() + 2 * ImGui::GetStyle().WindowPadding.y;
  ImGui::SetNextWindowPos(ImVec2(view.win_x, view.win_h - height), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(view.win_w, height), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("##status", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                        ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing);
  const viewer::JobStatus status = job_.status();
  if (status.running) {
    char overlay[128];
    std::snprintf(overlay, sizeof overlay, "%s %.0f%%", status.step.c_str(), 100 * status.fraction);
    ImGui::ProgressBar(float(status.fraction), ImVec2(220, 0), overlay);
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) job_.cancel();
    ImGui::SameLine();
  }
  if (state_.message_is_error) {
    ImGui::TextColored(ImVec4(1, 0.45f, 0.4f, 1), "%s", state_.message.c_str());
  } else {
    ImGui::TextUnformatted(state_.message.c_str());
  }
  ImGui::End();
}

void ViewerApp::draw_quality_legend(const ViewRect& view) {
  std::vector<bool> visible(state_.scene.parts.size());
  for (size_t i = 0; i < visible.size(); ++i) visible[i] = state_.scene.parts[i].visible;
  const viewer::PartStats all = viewer::combine_stats(state_.stats, visible);
  const float width = 300;
  ImGui::SetNextWindowPos(ImVec2(view.win_x + view.win_w - width - 10, 10), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(width, 0), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("Triangle quality (radii ratio)", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoSavedSettings);
  // The colour bar: the renderer's ramp, blue (0) to green (1) (quality_colors in quality.hpp).
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float bar_w = ImGui::GetContentRegionAvail().x, bar_h = 14;
  const ImU32 blue = IM_COL32(0, 0, 255, 255), green = IM_COL32(0, 255, 0, 255);
  ImGui::GetWindowDrawList()->AddRectFilledMultiColor(p, ImVec2(p.x + bar_w, p.y + bar_h), blue, green, green, blue);
  ImGui::Dummy(ImVec2(bar_w, bar_h));
  ImGui::Text("0");
  ImGui::SameLine(bar_w - ImGui::CalcTextSize("1").x);
  ImGui::Text("1");
  float bins[10];
  float top = 0;
  for (int b = 0; b < 10; ++b) top = std::max(top, bins[b] = float(all.rho_histogram[b]));
  ImGui::PlotHistogram("##histogram", bins, 10, 0, nullptr, 0, top * 1.05f + 1, ImVec2(bar_w, 70));
  ImGui::TextDisabled("triangles per 0.1 of radii ratio, visible parts");
  ImGui::Text("min %.3f, mean %.3f, %lld triangles", all.rho_min, all.rho_mean, (long long)all.triangles);
  ImGui::End();
}

void ViewerApp::draw_error_modal() {
  if (show_error_) {
    ImGui::OpenPopup("Problem");
    show_error_ = false;
  }
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x + vp->WorkSize.x / 2, vp->WorkPos.y + vp->WorkSize.y / 2),
                          ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(520, 0), ImGuiCond_Appearing);
  if (ImGui::BeginPopupModal("Problem", nullptr, ImGuiWindowFlags_NoSavedSettings)) {
    ImGui::TextWrapped("%s", state_.message.c_str());
    ImGui::TextDisabled("The scene is unchanged.");
    if (ImGui::Button("OK") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Enter))) {
      ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
  }
}

void ViewerApp::handle_dialog() {
  const std::optional<fs::path> chosen = dialog_.draw();
  if (!chosen) return;
  if (dialog_.purpose() == "open") {
    open_path(*chosen);
  } else if (dialog_.purpose() == "glb") {
    try {
      viewer::save_scene_glb(state_, *chosen);
      set_message(state_, "saved " + chosen->string());
    } catch (const Error& e) {
      set_message(state_, e.what(), true);
      show_error_ = true;
    }
  } else if (dialog_.purpose() == "png") {
    if (chosen->extension() != ".png" && chosen->extension() != ".PNG") {
      set_message(state_, chosen->string() + ": screenshots are saved as PNG; name it *.png", true);
      show_error_ = true;
      return;
    }
    // Taken two frames later, when the dialog is gone from the picture.
    pending_screenshot_ = *chosen;
    screenshot_countdown_ = 2;
  }
}

}  // namespace segmesh::viewer_app
