// A URDF file through the loader, as a world's `model: robot.urdf` imports
// it: one copy with its base fixed and one floating (urdf.h: urdfdom, the
// element lines, the link groups, meshes). package:// URIs resolve through
// the repository's worlds/models (simple_arm_description's tool.stl).
#include "framework/error.h"
#include "swarm/loader/world_loader.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

constexpr char kWorld[] = R"(# The URDF fuzzer's world: fuzz.urdf, fixed and floating.
simulation: {physics: ode, time_step: 0.1, physics_substeps: 2, seed: 1, steps: 1}
arena: {size: 6}
models:
  - model: fuzz.urdf
    count: 1
    position: [-1, 0]
  - model: fuzz.urdf
    count: 1
    position: [1, 0]
    base: floating
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path folder = [] {
    const std::filesystem::path dir = fuzz::TempFolder() / "urdf";
    std::filesystem::create_directories(dir);
    fuzz::WriteFile(dir / "world.yaml", kWorld);
    return dir;
  }();
  fuzz::WriteFile(folder / "fuzz.urdf", data, size);
  LoadOptions options;
  options.threads = 1;
  options.package_path = {fuzz::SourceDir() / "worlds" / "models"};
  try {
    LoadedWorld loaded = LoadWorld(folder / "world.yaml", options, fuzz::Registry());
  } catch (const Error& e) {
    fuzz::Rejected(e.what());
  }
  return 0;
}
