// A Lua script through the sandbox: a world with one robot whose body runs
// the input as its script (sysCall_init, then three steps of sensing and
// actuation, then sysCall_cleanup), under a small instruction budget and
// memory limit, as `swarmsim run` runs it (not trusted, no output folder,
// so no file may be written). The robot has wheels, a proximity ring and a
// LED, so that the sim.* calls of scripts/ find objects to act on.
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>

#include "framework/error.h"
#include "swarm/loader/world_loader.h"
#include "tools/fuzz/fuzz_support.h"

namespace {

constexpr char kWorld[] = R"(# The Lua fuzzer's world: one robot running fuzz.lua.
simulation:
  physics: box2d
  time_step: 0.1
  physics_substeps: 2
  seed: 1
  steps: 3
  instruction_budget: 50000
  script_memory_mb: 32
  octree_resolution: 0.25
arena: {size: 1.2}
obstacles:
  - {shape: box, size: [0.1, 0.1, 0.1], position: [0.3, 0, 0.05]}
models:
  - model: fuzz_bot.yaml
    count: 1
    position: [0, 0]
)";

constexpr char kModel[] = R"(# A foot-bot-like robot whose body runs fuzz.lua.
model: fuzz_bot
parameters:
  wheel_speed: {default: 0.05, unit: m/s}
  wheel_radius: {default: 0.029, unit: m}
objects:
  name: body
  type: shape
  shape: cylinder
  radius: 0.085
  height: 0.146
  dynamic: true
  mass: 1.6
  script: fuzz.lua
  children:
    - name: leftMotor
      type: joint
      joint: revolute
      mode: velocity
      max_force: 10
      position: [0, 0.07, -0.044]
      orientation_deg: [-90, 0, 0]
      children:
        - {name: leftWheel, type: shape, shape: cylinder, radius: 0.029, height: 0.02}
    - name: rightMotor
      type: joint
      joint: revolute
      mode: velocity
      max_force: 10
      position: [0, -0.07, -0.044]
      orientation_deg: [-90, 0, 0]
      children:
        - {name: rightWheel, type: shape, shape: cylinder, radius: 0.029, height: 0.02}
    - {type: proximity_ring, name: prox, count: 24, radius: 0.085, height: -0.013, range: 0.3}
    - {name: led, type: led, position: [0, 0, 0.083], radius: 0.01, color: [1, 1, 1]}
)";

constexpr int kSteps = 3;

// A finding: a script that has no output folder wrote a file beside it.
void CheckNothingWritten(const std::filesystem::path& folder) {
  static const std::set<std::string> kOurs = {"world.yaml", "fuzz_bot.yaml", "fuzz.lua"};
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    if (kOurs.count(entry.path().filename().string())) continue;
    std::fprintf(stderr, "lua fuzzer: a sandboxed script without an output folder wrote %s\n",
                 entry.path().c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace swarmsim;
  static const std::filesystem::path folder = [] {
    const std::filesystem::path dir = fuzz::TempFolder() / "lua";
    std::filesystem::create_directories(dir);
    fuzz::WriteFile(dir / "world.yaml", kWorld);
    fuzz::WriteFile(dir / "fuzz_bot.yaml", kModel);
    return dir;
  }();
  fuzz::WriteFile(folder / "fuzz.lua", data, size);
  LoadOptions options;
  options.threads = 1;
  try {
    LoadedWorld loaded = LoadWorld(folder / "world.yaml", options, fuzz::Registry());
    World& world = *loaded.world;
    world.set_log_sink([](std::string_view) {});
    world.Start();
    for (int i = 0; i < kSteps; ++i) world.Step();
    world.Stop();
  } catch (const Error& e) {
    // A script error (or a refused call), as the run reports it.
    fuzz::Rejected(e.what());
  }
  CheckNothingWritten(folder);
  return 0;
}
