#include "framework/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace swarmsim {
namespace {

// What a file that is not a regular one is, for the message refusing it.
std::string FileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

}  // namespace

bool SameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  if (std::filesystem::equivalent(a, b, ec)) return true;
  std::error_code ea, eb;
  const std::filesystem::path pa = std::filesystem::weakly_canonical(a, ea);
  const std::filesystem::path pb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && pa == pb;
}

std::string NotAnOrdinaryFile(const std::filesystem::path& path) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0 || S_ISREG(status.st_mode)) return "";
  return "it is " + FileTypeName(status.st_mode) + ", not an ordinary file";
}

std::unique_ptr<RegularFile> RegularFile::Open(const std::filesystem::path& path,
                                               std::string* why) {
  // O_NONBLOCK: opening a FIFO for reading returns at once instead of
  // waiting for a writer; it is refused below. Regular files ignore it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    *why = std::strerror(errno);
    return nullptr;
  }
  struct stat status {};
  if (::fstat(fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    *why = FileTypeName(status.st_mode);
    ::close(fd);
    return nullptr;
  }
  return std::unique_ptr<RegularFile>(new RegularFile(fd));
}

RegularFile::~RegularFile() { ::close(fd_); }

int64_t RegularFile::CurrentSize() const {
  struct stat status {};
  if (::fstat(fd_, &status) != 0) return -1;
  return static_cast<int64_t>(status.st_size);
}

bool RegularFile::ReadAt(uint64_t offset, char* out, size_t n, std::string* why) const {
  if (why != nullptr) why->clear();
  while (n > 0) {
    const ssize_t got = ::pread(fd_, out, n, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0 && why != nullptr) *why = std::strerror(errno);
    if (got <= 0) return false;  // an error, or the end of the file
    out += got;
    offset += static_cast<uint64_t>(got);
    n -= static_cast<size_t>(got);
  }
  return true;
}

}  // namespace swarmsim
