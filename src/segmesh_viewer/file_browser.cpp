#include "segmesh_viewer/file_browser.hpp"

#include <algorithm>
#include <cctype>

namespace segmesh::viewer {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

}  // namespace

FolderListing list_folder(const fs::path& folder, bool show_hidden) {
  FolderListing listing;
  std::error_code ec;
  listing.folder = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  if (ec) listing.folder = folder;
  fs::directory_iterator it(listing.folder, fs::directory_options::skip_permission_denied, ec);
  if (ec) {
    listing.error = listing.folder.string() + ": " + ec.message();
    return listing;
  }
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) break;
    const std::string name = it->path().filename().string();
    if (!show_hidden && !name.empty() && name[0] == '.') continue;
    std::error_code type_ec;
    listing.entries.push_back({name, it->is_directory(type_ec)});
  }
  std::sort(listing.entries.begin(), listing.entries.end(),
            [](const BrowserEntry& a, const BrowserEntry& b) {
              if (a.directory != b.directory) return a.directory;
              const std::string la = lower(a.name), lb = lower(b.name);
              return la != lb ? la < lb : a.name < b.name;
            });
  return listing;
}

fs::path parent_folder(const fs::path& folder) {
  fs::path f = folder.lexically_normal();
  if (!f.has_filename() && f != f.root_path()) f = f.parent_path();  // "a/b/" -> "a/b"
  const fs::path parent = f.parent_path();
  return parent.empty() ? f : parent;
}

}  // namespace segmesh::viewer
