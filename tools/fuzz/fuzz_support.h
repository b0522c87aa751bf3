// Shared by the fuzz harnesses (tools/fuzz/*_fuzzer.cc): a temporary folder
// of this process, files written into it, the source tree's folders and the
// module registry. Each harness defines LLVMFuzzerTestOneInput; libFuzzer
// (the fuzz preset) or replay_main.cc (every other build) calls it.
//
// A harness lets swarmsim::Error through its own catch (a user's mistake,
// reported as the program reports it) and nothing else: any other
// exception, a crash, an abort, a leak or a hang is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace swarmsim {
class ModuleRegistry;
}  // namespace swarmsim

namespace swarmsim::fuzz {

// A folder of this process's own under $TMPDIR (or /tmp), made on first
// use and removed at exit: swarmsim-fuzz-NAME-XXXXXX.
const std::filesystem::path& TempFolder();

// Writes `bytes` to `file` (replacing it). Aborts when it cannot: the
// harness, not the input, is broken then.
void WriteFile(const std::filesystem::path& file, std::string_view bytes);
inline void WriteFile(const std::filesystem::path& file, const uint8_t* data, size_t size) {
  WriteFile(file, std::string_view(reinterpret_cast<const char*>(data), size));
}

// The source tree this harness was built from (worlds/, scripts/, tests/data/).
std::filesystem::path SourceDir();

// A world folder inside TempFolder() that sees the repository's worlds,
// models and scripts as a world in worlds/ does: TempFolder()/worlds holds
// links to every entry of worlds/ and of tests/data/cli/, its models/
// folder links to every file of worlds/models/ and tests/data/worlds/models/,
// and TempFolder()/scripts links to scripts/. Returns TempFolder()/worlds.
const std::filesystem::path& WorldsMirror();

// An input the code refused with swarmsim::Error: printed when
// SWARMSIM_FUZZ_VERBOSE is set (to see what seeds reach), else nothing.
void Rejected(const char* message);

// The built-in modules, registered once.
const ModuleRegistry& Registry();

}  // namespace swarmsim::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
