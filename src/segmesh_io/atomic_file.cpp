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
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  require_parent_folder(target_);
  if (fs::is_directory(target_)) {
    throw Error(target_.string() + ": is a folder, not a file name");
  }
  static std::atomic<unsigned> counter{0};
  const std::string name = ".tmp-" + std::to_string(::getpid()) + "-" +
                           std::to_string(counter++) + "-" + target_.filename().string();
  temp_ = target_.parent_path() / name;
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    if (stream_.is_open()) stream_.close();
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

std::ofstream& AtomicFile::stream() {
  if (!stream_.is_open()) {
    stream_.open(temp_, std::ios::binary | std::ios::trunc);
    if (!stream_) {
      throw Error(target_.string() + ": cannot create a file in " +
                  (target_.parent_path().empty() ? std::string(".")
                                                 : target_.parent_path().string()) +
                  " (" + std::strerror(errno) + "); check the folder's permissions");
    }
  }
  return stream_;
}

void AtomicFile::commit() {
  if (stream_.is_open()) {
    stream_.flush();
    const bool ok = static_cast<bool>(stream_);
    stream_.close();
    if (!ok || stream_.fail()) {
      throw Error(target_.string() +
                  ": writing failed (disk full or no permission?); nothing was written");
    }
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
