// LD_PRELOAD'ed into the program by run_outputs_test: raises SIGTERM in it
// at its first write to a file named recording.swrec once the summary.json
// beside that file says the run is "ok": a stop signal that arrives after
// the summary was written, while the recording's end is being written (the
// program's last output). It leaves a file `late_signal_raised` beside them.
#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstring>

namespace {

bool raised = false;

// Does the file `fd` names end in recording.swrec, with a summary.json beside
// it that says "ok"? `folder` gets the folder, with its '/'.
bool AfterTheSummary(int fd, char (&folder)[4096]) {
  char link[64];
  std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t length = readlink(link, folder, sizeof folder - 32);
  constexpr const char* kRecording = "recording.swrec";
  const size_t name = std::strlen(kRecording);
  if (length < static_cast<ssize_t>(name)) return false;
  folder[length] = '\0';
  if (std::strcmp(folder + length - name, kRecording) != 0) return false;
  folder[length - name] = '\0';
  char path[4096 + 32];
  std::snprintf(path, sizeof path, "%ssummary.json", folder);
  const int summary = open(path, O_RDONLY);
  if (summary < 0) return false;
  char text[16384];
  const ssize_t n = read(summary, text, sizeof text - 1);
  close(summary);
  if (n <= 0) return false;
  text[n] = '\0';
  return std::strstr(text, "\"status\": \"ok\"") != nullptr;
}

}  // namespace

extern "C" ssize_t write(int fd, const void* bytes, size_t count) {
  using Write = ssize_t (*)(int, const void*, size_t);
  static const auto real = reinterpret_cast<Write>(dlsym(RTLD_NEXT, "write"));
  char folder[4096];
  if (!raised && AfterTheSummary(fd, folder)) {
    raised = true;
    char marker[4096 + 32];
    std::snprintf(marker, sizeof marker, "%slate_signal_raised", folder);
    close(open(marker, O_WRONLY | O_CREAT, 0644));
    raise(SIGTERM);
  }
  return real(fd, bytes, count);
}
