// An OctoMap file (.bt, or .ot when the input's first line says so) through
// the loader, as a world's `environment: {octomap: FILE}` reads it
// (modules/environment: the format checks, then the library, then the
// occupied leaves as boxes), with two robots placed around the map's voxels.
#include <string_view>

#include "framework/error.h"
#include "modules/environment/octomap_format.h"
#include "swarm/loader/world_loader.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

constexpr char kWorld[] = R"(# The OctoMap fuzzer's world: fuzz.bt (or fuzz.ot) as the environment.
simulation: {physics: box2d, time_step: 0.1, physics_substeps: 2, seed: 1, steps: 1}
arena: {size: 4}
environment: {octomap: $map, z_range: [-1, 2], max_memory_mb: 64}
parameters: {map: fuzz.bt}
models:
  - model: bot.yaml
    count: 2
    distribute: {region: arena}
)";

constexpr char kBot[] = R"(model: bot
objects: {name: body, type: shape, shape: cylinder, radius: 0.05, height: 0.05, dynamic: true}
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path folder = [] {
    const std::filesystem::path dir = fuzz::TempFolder() / "octomap";
    std::filesystem::create_directories(dir);
    fuzz::WriteFile(dir / "world.yaml", kWorld);
    fuzz::WriteFile(dir / "bot.yaml", kBot);
    return dir;
  }();
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const bool full = bytes.starts_with(environment::kFullFirstLine) &&
                    !bytes.starts_with(environment::kBinaryFirstLine);
  const std::string name = full ? "fuzz.ot" : "fuzz.bt";
  fuzz::WriteFile(folder / name, bytes);
  LoadOptions options;
  options.threads = 1;
  options.overrides = {{"map", name}};
  try {
    LoadedWorld loaded = LoadWorld(folder / "world.yaml", options, fuzz::Registry());
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  return 0;
}
