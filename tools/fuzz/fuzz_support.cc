#include "tools/fuzz/fuzz_support.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <system_error>

namespace swarmsim::fuzz {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void Die(const std::string& message) {
  std::fprintf(stderr, "fuzz harness: %s\n", message.c_str());
  std::abort();
}

void RemoveTempFolder() {
  std::error_code ec;
  fs::remove_all(TempFolder(), ec);
}

// Links `link` to `target` unless it exists already.
void Link(const fs::path& target, const fs::path& link) {
  std::error_code ec;
  if (fs::exists(fs::symlink_status(link, ec))) return;
  fs::create_symlink(target, link, ec);
  if (ec) Die("cannot link " + link.string() + " to " + target.string() + ": " + ec.message());
}

// Links every entry of `from` into `into` (first come, first linked).
void LinkEntries(const fs::path& from, const fs::path& into) {
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(from, ec))
    Link(entry.path(), into / entry.path().filename());
}

}  // namespace

const fs::path& TempFolder() {
  static const fs::path folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string name = std::string(tmp && *tmp ? tmp : "/tmp") + "/swarmsim-fuzz-" +
                       std::to_string(getpid()) + "-XXXXXX";
    if (!mkdtemp(name.data())) Die("cannot make a temporary folder " + name);
    std::atexit(RemoveTempFolder);
    return fs::path(name);
  }();
  return folder;
}

void WriteFile(const fs::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) Die("cannot write " + file.string());
}

void Rejected(const char* message) {
  static const bool verbose = std::getenv("SWARMSIM_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "refused: %s\n", message);
}

fs::path SourceDir() { return SWARMSIM_SOURCE_DIR; }

const fs::path& WorldsMirror() {
  static const fs::path worlds = [] {
    const fs::path root = TempFolder();
    const fs::path source = SourceDir();
    std::error_code ec;
    fs::create_directories(root / "worlds" / "models", ec);
    if (ec) Die("cannot make " + (root / "worlds/models").string());
    LinkEntries(source / "worlds" / "models", root / "worlds" / "models");
    LinkEntries(source / "tests" / "data" / "worlds" / "models", root / "worlds" / "models");
    LinkEntries(source / "worlds", root / "worlds");
    LinkEntries(source / "tests" / "data" / "cli", root / "worlds");
    Link(source / "scripts", root / "scripts");
    return root / "worlds";
  }();
  return worlds;
}

}  // namespace swarmsim::fuzz
