// The in-window file dialog: a Dear ImGui modal that browses folders (segmesh_viewer's
// file_browser.hpp lists them) to open a file or a DICOM folder, or to choose where to save.
// No external dialog library, so it looks and works the same everywhere, under Xvfb included.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "segmesh_viewer/file_browser.hpp"

namespace segmesh::viewer_app {

class FileDialog {
 public:
  enum class Mode { open, save };

  // Opens the dialog (shown from the next draw()); `suggested_name` fills the file name in save
  // mode, `purpose` identifies the caller ("open", "glb", "png").
  void open(Mode mode, std::string title, std::string purpose, std::string suggested_name = "");
  // Draws the dialog when open; returns the chosen path once, when the user confirms.
  std::optional<std::filesystem::path> draw();
  const std::string& purpose() const { return purpose_; }

 private:
  void refresh();

  Mode mode_ = Mode::open;
  std::string title_, purpose_;
  bool open_requested_ = false;
  std::filesystem::path folder_ = std::filesystem::current_path();
  viewer::FolderListing listing_;
  bool show_hidden_ = false;
  char name_[512] = {};
  int selected_ = -1;
};

}  // namespace segmesh::viewer_app
