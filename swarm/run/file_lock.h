// An exclusive lock of one file (flock) that says who holds it: what keeps
// a second sweep off a results database and a second run out of an output
// folder. The file holds the holder's process id and is removed when the
// lock is released (while still held).
#pragma once

#include <string>

namespace swarmsim {

class FileLock {
 public:
  // Creates `path` if needed and tries to lock it, without waiting. Throws
  // swarmsim::Error naming `path` when it cannot be created.
  explicit FileLock(std::string path);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

  // Whether this process holds it; if not, another does: holder() is its
  // process id as it wrote it ("" if it wrote none yet).
  bool held() const { return fd_ >= 0; }
  // Removes the file and lets the lock go now (a run that ends without
  // returning: a stuck step's watchdog). Nothing if not held; idempotent.
  void Release();
  const std::string& holder() const { return holder_; }

 private:
  std::string path_;
  std::string holder_;
  int fd_ = -1;
};

}  // namespace swarmsim
