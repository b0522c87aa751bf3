#include "framework/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "framework/error.h"
#include "framework/regular_file.h"

namespace swarmsim {
namespace {

// Writes all of `bytes` to `fd`; errno's text on failure, else "".
std::string WriteAll(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return std::strerror(errno);
    }
    done += static_cast<size_t>(n);
  }
  return "";
}

}  // namespace

std::string CannotWrite(const std::filesystem::path& path) {
  const int error = errno;
  return "cannot write '" + path.string() + "'" +
         (error != 0 ? std::string(": ") + std::strerror(error) : std::string());
}

std::string TryWriteFileAtomically(const std::filesystem::path& given, std::string_view bytes) {
  namespace fs = std::filesystem;
  // A device, a pipe or a folder is not replaced by a file (--save-state
  // /dev/null turned the system's /dev/null into one); a symbolic link is
  // written through, its target replaced, not the link.
  if (std::string reason = NotAnOrdinaryFile(given); !reason.empty()) return reason;
  std::error_code ec;
  fs::path path = given;
  for (int links = 0; fs::is_symlink(path, ec); ++links) {  // to a file not there yet too
    if (links == 40) return "it is a loop of symbolic links";
    const fs::path target = fs::read_symlink(path, ec);
    if (ec) return ec.message();
    path = target.is_absolute() ? target : path.parent_path() / target;
  }
  std::filesystem::path partial = path;
  partial += ".partial";
  const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return std::strerror(errno);
  std::string reason = WriteAll(fd, bytes);
  // A full disk may only show at the close (network file systems).
  if (::close(fd) != 0 && reason.empty()) reason = std::strerror(errno);
  if (reason.empty() && ::rename(partial.c_str(), path.c_str()) != 0) reason = std::strerror(errno);
  if (!reason.empty()) ::unlink(partial.c_str());
  return reason;
}

void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes) {
  const std::string reason = TryWriteFileAtomically(path, bytes);
  if (!reason.empty()) throw Error("cannot write '" + path.string() + "': " + reason);
}

OutputReserve::~OutputReserve() { Release(); }

bool OutputReserve::Reserve(const std::filesystem::path& folder, size_t bytes) {
  Release();
  file_ = folder / ".swarmsim-reserve";
  const int fd = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    file_.clear();
    return false;
  }
  // Real blocks, not a sparse file: written zeros (posix_fallocate is not
  // on every file system the output may be on, tmpfs included in old kernels).
  const std::vector<char> zeros(bytes, 0);
  const bool ok =
      WriteAll(fd, std::string_view(zeros.data(), zeros.size())).empty() && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) Release();
  return ok;
}

void OutputReserve::Release() {
  if (file_.empty()) return;
  ::unlink(file_.c_str());
  file_.clear();
}

}  // namespace swarmsim
