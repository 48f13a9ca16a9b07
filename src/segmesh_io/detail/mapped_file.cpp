#include "segmesh_io/detail/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace segmesh::volume_io {

MappedFile::MappedFile(const std::filesystem::path& path, uint64_t offset) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error_ = errno;
    return;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    error_ = errno;
  } else if (!S_ISREG(st.st_mode)) {
    error_ = EINVAL;
  } else {
    const auto file_size = static_cast<uint64_t>(st.st_size);
    opened_ = true;
    if (file_size > offset) {
      void* map = ::mmap(nullptr, file_size, PROT_READ, MAP_PRIVATE, fd, 0);
      if (map == MAP_FAILED) {
        error_ = errno;
        opened_ = false;
      } else {
        map_ = map;
        map_size_ = file_size;
        data_ = static_cast<const unsigned char*>(map) + offset;
        size_ = file_size - offset;
      }
    }
  }
  ::close(fd);  // the mapping stays valid
}

MappedFile::~MappedFile() {
  if (map_) ::munmap(map_, map_size_);
}

void MappedFile::advise_sequential() const {
  if (map_) ::madvise(map_, map_size_, MADV_SEQUENTIAL);
}

}  // namespace segmesh::volume_io
