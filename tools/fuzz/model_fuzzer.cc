// A model file (worlds/models/*.yaml) through the loader: a fixed world
// places two copies of it (read, resolved with its parameters' defaults,
// built and copied), as `swarmsim run` loads any world naming a model. The
// model sits beside the repository's models (WorldsMirror), so that its
// scripts and meshes resolve as theirs do.
#include "framework/error.h"
#include "swarm/loader/world_loader.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

constexpr char kWorld[] = R"(# The model fuzzer's world: two copies of models/fuzz_model.yaml.
simulation: {physics: box2d, time_step: 0.1, physics_substeps: 2, seed: 1, steps: 1}
arena: {size: 4}
models:
  - model: models/fuzz_model.yaml
    count: 2
    distribute: {region: arena}
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path world = [] {
    const std::filesystem::path file = fuzz::WorldsMirror() / "fuzz_model_world.yaml";
    fuzz::WriteFile(file, kWorld);
    return file;
  }();
  fuzz::WriteFile(fuzz::WorldsMirror() / "models" / "fuzz_model.yaml", data, size);
  LoadOptions options;
  options.threads = 1;
  try {
    LoadedWorld loaded = LoadWorld(world, options, fuzz::Registry());
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  return 0;
}
