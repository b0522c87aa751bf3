// Output files a run writes whole (summary.json, graph CSVs, PNG snapshots,
// paint.png, exported pages): written beside their final name, flushed and
// checked, then renamed over it, so a reader (a batch system, a sweep, a
// colleague) sees the old file or the new one, never half of one, and a full
// disk is an error that names the file instead of a silent empty file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace swarmsim {

// Writes `bytes` to `path` atomically: to `path` + ".partial" in the same
// folder, closed with every error checked, then
// renamed over `path` (not fsync'd: safe against a crash of the program, not
// of the machine). On failure the partial file is removed, `path` keeps
// what it held, and Error says which file and why ("No space left on
// device").
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// As WriteFileAtomically, but returns the reason instead of throwing: "" when
// written. For paths that must not throw (a run's last words). Both refuse
// a path that is a device, a named pipe, a socket or a folder
// (NotAnOrdinaryFile, regular_file.h), and write through a symbolic link (its target is
// replaced, the link stays).
std::string TryWriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// "cannot write 'PATH': REASON", REASON from errno as an open or a write of
// PATH just left it (nothing when errno is 0): for a stream that would not
// open.
std::string CannotWrite(const std::filesystem::path& path);

// Space kept aside in an output folder so that the run's last file
// (summary.json) can still be written when the disk fills up during the run
// (a video, a recording). Reserve() writes a hidden file of `bytes`;
// Release() removes it, just before the last write. Best effort: on a disk
// already full, Reserve() keeps nothing and says so by returning false.
class OutputReserve {
 public:
  OutputReserve() = default;
  ~OutputReserve();  // removes the file if still there
  OutputReserve(const OutputReserve&) = delete;
  OutputReserve& operator=(const OutputReserve&) = delete;

  bool Reserve(const std::filesystem::path& folder, size_t bytes);
  void Release();

 private:
  std::filesystem::path file_;
};

}  // namespace swarmsim
