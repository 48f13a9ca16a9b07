// The in-window file dialog's logic: listing a folder for a simple directory browser (no external
// dialog library). Folders first, then files, each sorted by name (case-insensitive); hidden
// entries (a leading dot) only when asked. Which files can be opened is decided when they are
// opened (load_input.hpp), so every file is listed; a folder can be opened as a DICOM series.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace segmesh::viewer {

struct BrowserEntry {
  std::string name;
  bool directory = false;
};

struct FolderListing {
  std::filesystem::path folder;     // absolute, normalised
  std::vector<BrowserEntry> entries;
  std::string error;                // non-empty when the folder could not be read (entries empty)
};

FolderListing list_folder(const std::filesystem::path& folder, bool show_hidden = false);

// The folder one level up (the folder itself at the root).
std::filesystem::path parent_folder(const std::filesystem::path& folder);

}  // namespace segmesh::viewer
