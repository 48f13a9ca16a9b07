#include "file_dialog.hpp"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace segmesh::viewer_app {

namespace fs = std::filesystem;

void FileDialog::open(Mode mode, std::string title, std::string purpose, std::string suggested_name) {
  mode_ = mode;
  title_ = std::move(title);
  purpose_ = std::move(purpose);
  std::snprintf(name_, sizeof name_, "%s", suggested_name.c_str());
  open_requested_ = true;
  selected_ = -1;
  refresh();
}

void FileDialog::refresh() {
  listing_ = viewer::list_folder(folder_, show_hidden_);
  folder_ = listing_.folder;
  selected_ = -1;
}

std::optional<fs::path> FileDialog::draw() {
  const std::string id = title_ + "###file_dialog";
  if (open_requested_) {
    ImGui::OpenPopup(id.c_str());
    open_requested_ = false;
  }
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowSize(ImVec2(std::min(640.0f, vp->WorkSize.x - 40), std::min(480.0f, vp->WorkSize.y - 40)),
                           ImGuiCond_Appearing);
  ImGui::SetNextWindowPos(ImVec2(vp->WorkPos.x + vp->WorkSize.x / 2, vp->WorkPos.y + vp->WorkSize.y / 2),
                          ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
  std::optional<fs::path> chosen;
  if (!ImGui::BeginPopupModal(id.c_str(), nullptr)) return chosen;

  if (ImGui::Button("Up")) {
    folder_ = viewer::parent_folder(folder_);
    refresh();
  }
  ImGui::SameLine();
  if (ImGui::Button("Home")) {
    if (const char* home = std::getenv("HOME")) folder_ = home;
    refresh();
  }
  ImGui::SameLine();
  if (ImGui::Button("Refresh")) refresh();
  ImGui::SameLine();
  if (ImGui::Checkbox("Hidden files", &show_hidden_)) refresh();
  ImGui::TextWrapped("%s", folder_.string().c_str());
  if (!listing_.error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", listing_.error.c_str());

  const float footer = ImGui::GetFrameHeightWithSpacing() * 2 + ImGui::GetStyle().ItemSpacing.y;
  ImGui::BeginChild("entries", ImVec2(0, -footer), true);
  std::optional<fs::path> enter;
  for (int i = 0; i < int(listing_.entries.size()); ++i) {
    const viewer::BrowserEntry& e = listing_.entries[i];
    const std::string label = (e.directory ? "[dir] " : "      ") + e.name;
    if (ImGui::Selectable(label.c_str(), selected_ == i, ImGuiSelectableFlags_AllowDoubleClick)) {
      selected_ = i;
      if (!e.directory || mode_ == Mode::open) std::snprintf(name_, sizeof name_, "%s", e.name.c_str());
      if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) {
        if (e.directory) {
          enter = folder_ / e.name;
        } else {
          chosen = folder_ / e.name;
        }
      }
    }
  }
  ImGui::EndChild();
  if (enter) {
    folder_ = *enter;
    refresh();
    if (mode_ == Mode::open) name_[0] = 0;
  }

  ImGui::SetNextItemWidth(-1);
  const bool entered = ImGui::InputText("##name", name_, sizeof name_, ImGuiInputTextFlags_EnterReturnsTrue);
  const bool have_name = std::strlen(name_) > 0;
  if (ImGui::Button(mode_ == Mode::open ? "Open" : "Save") || (entered && have_name)) {
    if (have_name) {
      const fs::path p = fs::path(name_).is_absolute() ? fs::path(name_) : folder_ / name_;
      std::error_code ec;
      if (mode_ == Mode::open && fs::is_directory(p, ec) && !chosen) {
        // A folder: "Open" on a selected folder goes into it; "Open folder" opens it as DICOM.
        folder_ = p;
        refresh();
        name_[0] = 0;
      } else {
        chosen = p;
      }
    }
  }
  if (mode_ == Mode::open) {
    ImGui::SameLine();
    if (ImGui::Button("Open this folder (DICOM series)")) chosen = folder_;
  }
  ImGui::SameLine();
  if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
    ImGui::CloseCurrentPopup();
  }
  if (chosen) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
  return chosen;
}

}  // namespace segmesh::viewer_app
