// A file opened for reading at any offset, and only if it is a regular
// file: opened non-blocking and checked with fstat, so that a FIFO or a
// device put where a file was expected is refused, never waited on or read
// forever. Used by the readers of files a run wrote (recordings) and by the
// viewer's server.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

namespace swarmsim {

class RegularFile {
 public:
  // The open file, or null with `*why` set: the system's reason ("No such
  // file or directory"), or what it is instead ("a FIFO (named pipe)").
  static std::unique_ptr<RegularFile> Open(const std::filesystem::path& path, std::string* why);
  ~RegularFile();
  RegularFile(const RegularFile&) = delete;
  RegularFile& operator=(const RegularFile&) = delete;

  // Its size now (a file still being written grows); -1 when fstat fails.
  int64_t CurrentSize() const;
  // The `n` bytes at `offset` into `out`. False when the file ends before
  // them (`*why` empty) or a read fails (`*why`: the system's reason).
  bool ReadAt(uint64_t offset, char* out, size_t n, std::string* why = nullptr) const;

 private:
  explicit RegularFile(int fd) : fd_(fd) {}
  int fd_;
};

// "it is a FIFO (named pipe), not an ordinary file" when `path` (through
// symbolic links) is there and is no regular file (a folder, a device, a
// pipe, a socket); "" when it is one or is not there. For the writers that
// replace a file by renaming over it (output_file.h) and the checks of
// files the command line names.
std::string NotAnOrdinaryFile(const std::filesystem::path& path);

// Whether two names are one file: the same file when both exist (links,
// "./a" and "a"), else the same path once made absolute (a file yet to be
// written). For the commands that must not write one output over another
// or over their input (report, bench, results merge).
bool SameFile(const std::filesystem::path& a, const std::filesystem::path& b);

}  // namespace swarmsim
