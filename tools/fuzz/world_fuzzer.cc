// A world file (worlds/*.yaml) through the loader, as `swarmsim run` and
// `swarmsim describe` load it: LoadWorld, placed, not started. The input is
// the world file, in a folder that sees the repository's models and scripts
// (WorldsMirror), so that seeds from worlds/ and tests/data/worlds/ load.
#include <cstdint>
#include <string>

#include "framework/error.h"
#include "swarm/loader/world_loader.h"
#include "tools/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  const std::filesystem::path file = fuzz::WorldsMirror() / "fuzz_world.yaml";
  fuzz::WriteFile(file, data, size);
  LoadOptions options;
  options.threads = 1;
  // A world of many thousand robots is valid, and takes gigabytes under
  // ASan: past libFuzzer's memory limit, an out-of-memory "finding" that is
  // no bug (one stopped a run without its input being saved). Such worlds
  // are abandoned as they start placing or building their copies.
  constexpr int64_t kMaxCopies = 2000;
  options.progress = [](LoadOptions::LoadStage, int64_t, int64_t total) {
    if (total > kMaxCopies)
      throw Error("fuzz: " + std::to_string(total) + " copies, more than this harness builds");
  };
  try {
    LoadedWorld loaded = LoadWorld(file, options, fuzz::Registry());
  } catch (const Error& e) {
    // A user's mistake, reported as such.
    fuzz::Rejected(e.what());
  }
  return 0;
}
