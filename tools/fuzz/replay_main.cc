// The main() of a harness built without libFuzzer (every preset but fuzz):
// runs LLVMFuzzerTestOneInput once over each input named on the command
// line, so that the test suite replays the seed corpora and every past crash
// input (tools/fuzz/CMakeLists.txt registers one ctest per harness).
//
//   fuzz_replay_world [--ext .yaml,.yml] PATH... [--any] PATH...
//
// A PATH is a file or a folder (every file below it, recursively, in name
// order). --ext keeps only files with one of those extensions from the
// folders named after it, --any every file again; files named directly are
// always run. A crash, an abort or an exception other than swarmsim::Error
// ends the program as it would end libFuzzer's; a harness that finishes
// every input exits 0 and prints how many it ran and the slowest.
//
// Memory is capped (kMaxMemoryBytes of address space, except under ASan,
// which reserves terabytes): an input that makes the code allocate without
// bound ends in std::bad_alloc, a failed test, instead of taking the
// machine's memory.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "framework/sanitizers.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

namespace fs = std::filesystem;

constexpr rlim_t kMaxMemoryBytes = rlim_t{4} << 30;

using swarmsim::kAddressSanitizer;

std::set<std::string> SplitExtensions(const std::string& list) {
  std::set<std::string> out;
  std::stringstream in(list);
  for (std::string ext; std::getline(in, ext, ',');)
    if (!ext.empty()) out.insert(ext);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (!kAddressSanitizer) {
    const rlimit limit{kMaxMemoryBytes, kMaxMemoryBytes};
    setrlimit(RLIMIT_AS, &limit);
  }
  std::vector<fs::path> inputs;
  std::set<std::string> extensions;  // empty: every file
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--ext" && i + 1 < argc) {
      extensions = SplitExtensions(argv[++i]);
      continue;
    }
    if (arg == "--any") {
      extensions.clear();
      continue;
    }
    std::error_code ec;
    if (fs::is_regular_file(arg, ec)) {
      inputs.emplace_back(arg);
    } else if (fs::is_directory(arg, ec)) {
      std::vector<fs::path> found;
      for (const fs::directory_entry& e : fs::recursive_directory_iterator(arg, ec))
        if (e.is_regular_file(ec) &&
            (extensions.empty() || extensions.count(e.path().extension().string())))
          found.push_back(e.path());
      std::sort(found.begin(), found.end());
      inputs.insert(inputs.end(), found.begin(), found.end());
    } else {
      std::fprintf(stderr, "replay: no such file or folder, skipped: %s\n", arg.c_str());
    }
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "replay: no inputs\n");
    return 2;
  }
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  double slowest = 0;
  fs::path slowest_input;
  for (const fs::path& input : inputs) {
    std::ifstream in(input, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // Named before it runs, so that a crash shows which input it was.
    std::fprintf(stderr, "replay: %s\n", input.c_str());
    const Clock::time_point t0 = Clock::now();
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (seconds > slowest) slowest = seconds, slowest_input = input;
  }
  const double total = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("replay: %zu inputs in %.2f s; slowest %.3f s (%s)\n", inputs.size(), total, slowest,
              slowest_input.c_str());
  return 0;
}
