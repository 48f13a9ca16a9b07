// AtomicFile: write a file so that it either appears complete or not at all.
//
// Data goes to a temporary file in the target's own folder (same file system, so the final
// rename is atomic); commit() flushes, checks for write errors (a full disk, a lost permission) and
// renames it over the target. If commit() is never reached (an exception, a crash of this step),
// the destructor removes the temporary file and the target is untouched.
//
// A target that exists and is not a regular file (a device such as /dev/null or /dev/full, a
// named pipe) cannot be replaced by a rename; it is written directly, and write errors (ENOSPC
// from /dev/full) are reported the same way.
//
// Errors say why ("No space left on device", "Permission denied") with the target's name first.
//
// The temporary name keeps the target's full extension (".tmp-<pid>-<n>-scene.glb") so
// libraries that pick the format by extension (ITK) can write to temp_path() directly.
#pragma once

#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

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
  std::ostream& stream();

  // Closes the stream (if used), checks that every byte reached the disk and renames the
  // temporary file to the target. Throws segmesh::Error naming the target on failure.
  void commit();

  // Flushes and closes the stream and throws segmesh::Error naming the target and the reason
  // when any byte did not reach the file. commit() calls it; callers writing several files
  // call it to close each early.
  void close_stream();

 private:
  // A file buffer that keeps the errno of its first failed write: a stream stops writing quietly
  // after an error, so by the time the writer is done the reason would be lost.
  class Buffer : public std::filebuf {
   public:
    int error = 0;

   protected:
    int_type overflow(int_type c) override;
    std::streamsize xsputn(const char* s, std::streamsize n) override;
    int sync() override;
  };

  std::filesystem::path target_;
  std::filesystem::path temp_;
  Buffer buffer_;
  std::ostream stream_{nullptr};
  bool committed_ = false;
  bool direct_ = false;  // the target is a device or pipe, written in place
};

// "<path>: cannot write (<reason>); nothing was written", reason from `error` (an errno value)
// when it is set, else a guess naming both usual causes.
std::string write_failure(const std::filesystem::path& path, int error);

// Throws segmesh::Error("<path>: the folder <parent> does not exist ...") when `path` cannot be
// created because its parent folder is missing, is not a folder, or may not be written to
// (access(2): permission bits, a read-only file system).
void require_parent_folder(const std::filesystem::path& path);

// Whether two paths name the same file or folder, however spelled ("a.ply", "./a.ply"); neither
// needs to exist.
bool same_path(const std::filesystem::path& a, const std::filesystem::path& b);

// Throws segmesh::Error("<output>: is the input; ...") when `output` exists and is the same file as
// `input` (also through a link or another spelling of the path).
void refuse_to_overwrite(const std::filesystem::path& output, const std::filesystem::path& input);

}  // namespace segmesh
