// AtomicFile: write a file so that it either appears complete or not at all.
//
// Data goes to a temporary file in the target's own folder (same file system, so the final
// rename is atomic); commit() flushes, checks for write errors (a full disk, a lost permission) and
// renames it over the target. If commit() is never reached (an exception, a crash of this step),
// the destructor removes the temporary file and the target is untouched.
//
// The temporary name keeps the target's full extension (".tmp-<pid>-<n>-scene.glb") so
// libraries that pick the format by extension (ITK) can write to temp_path() directly.
#pragma once

#include <filesystem>
#include <fstream>

namespace segmesh {

class AtomicFile {
 public:
  // Throws segmesh::Error when the target's folder does not exist or the temporary file cannot be
  // created.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temp_path() const { return temp_; }

  // A binary stream on temp_path(), opened on first use.
  std::ofstream& stream();

  // Closes the stream (if used), checks that every byte reached the disk and renames the
  // temporary file to the target. Throws segmesh::Error naming the target on failure.
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::ofstream stream_;
  bool committed_ = false;
};

// Throws segmesh::Error("<path>: the folder <parent> does not exist ...") when `path` cannot be
// created because its parent folder is missing or is not a folder.
void require_parent_folder(const std::filesystem::path& path);

}  // namespace segmesh
