#include "swarm/run/file_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "framework/error.h"

namespace swarmsim {

FileLock::FileLock(std::string path) : path_(std::move(path)) {
  const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("cannot create the lock file '" + path_ + "': " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {};
    const ssize_t n = ::pread(fd, pid, sizeof pid - 1, 0);
    ::close(fd);
    holder_.assign(pid, n > 0 ? static_cast<size_t>(n) : 0);
    while (!holder_.empty() && (holder_.back() == '\n' || holder_.back() == ' '))
      holder_.pop_back();
    return;
  }
  fd_ = fd;
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    // The pid is only for the holder's message.
  }
}

FileLock::~FileLock() { Release(); }

void FileLock::Release() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // removed while still held
  ::close(fd_);
  fd_ = -1;
}

}  // namespace swarmsim
