#include "segmesh_io/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "segmesh/error.hpp"

namespace segmesh {

namespace fs = std::filesystem;

bool same_path(const fs::path& a, const fs::path& b) {
  std::error_code e1, e2;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a), e1);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b), e2);
  return e1 || e2 ? a == b : ca == cb;
}

void refuse_to_overwrite(const fs::path& output, const fs::path& input) {
  std::error_code ec;
  if (fs::exists(output, ec) && fs::equivalent(output, input, ec)) {
    throw Error(output.string() + ": is the input; choose another output path");
  }
}

void require_parent_folder(const fs::path& path) {
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  std::error_code ec;
  if (!fs::exists(parent, ec)) {
    throw Error(path.string() + ": the folder " + parent.string() +
                " does not exist; create it first or choose another output path");
  }
  if (!fs::is_directory(parent, ec)) {
    throw Error(path.string() + ": " + parent.string() + " is not a folder");
  }
  // Asked before any long work; root passes this check whatever the permission bits say, and a
  // later failure to create the file is still reported with its reason.
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    const int error = errno;
    throw Error(path.string() + ": cannot write in the folder " + parent.string() + " (" +
                std::strerror(error) + "); choose another output folder or fix its permissions");
  }
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  require_parent_folder(target_);
  std::error_code ec;
  const fs::file_status status = fs::status(target_, ec);
  if (fs::is_directory(status)) {
    throw Error(target_.string() + ": is a folder, not a file name");
  }
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    // A device or a pipe: renaming a temporary over it would replace the device node.
    direct_ = true;
    temp_ = target_;
    return;
  }
  static std::atomic<unsigned> counter{0};
  const std::string name = ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter++) + "-" + target_.filename().string();
  temp_ = target_.parent_path() / name;
}

AtomicFile::~AtomicFile() {
  if (buffer_.is_open()) buffer_.close();
  if (direct_) return;
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

AtomicFile::Buffer::int_type AtomicFile::Buffer::overflow(int_type c) {
  errno = 0;
  const int_type result = std::filebuf::overflow(c);
  if (traits_type::eq_int_type(result, traits_type::eof()) && error == 0) error = errno;
  return result;
}

std::streamsize AtomicFile::Buffer::xsputn(const char* s, std::streamsize n) {
  errno = 0;
  const std::streamsize written = std::filebuf::xsputn(s, n);
  if (written < n && error == 0) error = errno;
  return written;
}

int AtomicFile::Buffer::sync() {
  errno = 0;
  const int result = std::filebuf::sync();
  if (result != 0 && error == 0) error = errno;
  return result;
}

std::ostream& AtomicFile::stream() {
  if (!buffer_.is_open()) {
    errno = 0;
    if (!buffer_.open(temp_, std::ios::out | std::ios::binary | std::ios::trunc)) {
      const int error = errno;
      if (direct_) throw Error(write_failure(target_, error));
      throw Error(target_.string() + ": cannot create a file in " +
                  (target_.parent_path().empty() ? std::string(".")
                                                 : target_.parent_path().string()) +
                  " (" + (error ? std::strerror(error) : "unknown reason") +
                  "); check the folder's permissions and free space");
    }
    stream_.rdbuf(&buffer_);
    stream_.clear();
  }
  return stream_;
}

std::string write_failure(const fs::path& path, int error) {
  return path.string() + ": cannot write (" +
         (error != 0 ? std::string(std::strerror(error)) : std::string("disk full or no permission?")) +
         "); nothing was written";
}

void AtomicFile::close_stream() {
  if (!buffer_.is_open()) return;
  stream_.flush();
  bool ok = stream_.good();
  errno = 0;
  if (!buffer_.close()) {
    ok = false;
    if (buffer_.error == 0) buffer_.error = errno;
  }
  if (!ok) throw Error(write_failure(target_, buffer_.error));
}

void AtomicFile::commit() {
  close_stream();
  if (direct_) {
    committed_ = true;
    return;
  }
  std::error_code ec;
  if (!fs::exists(temp_, ec)) {
    throw Error(target_.string() + ": the output was not produced; nothing was written");
  }
  fs::rename(temp_, target_, ec);
  if (ec) {
    throw Error(target_.string() + ": cannot replace the file (" + ec.message() +
                "); nothing was written");
  }
  committed_ = true;
}

}  // namespace segmesh
