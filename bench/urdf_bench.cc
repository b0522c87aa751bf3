// Loading URDF descriptions (swarm/loader/urdf.cc): a generated 100-link
// arm (three in four joints revolute, one fixed; each link with an
// inertial, a box collision and a coloured cylinder visual, every tenth an
// STL tool), imported alone and loaded as a world (import, objects, ODE
// build); and TIAGo++ (130 links) of ../shared/urdf-corpus when it is there.
// Target (issue 31): a 100-link description loads in <= 0.3 s.
//   build/bench/urdf_bench
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/urdf.h"
#include "swarm/loader/world_loader.h"

namespace {

namespace fs = std::filesystem;

fs::path Folder() {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / ("swarmsim_urdf_bench_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// The 100-link arm; returns its path.
fs::path HundredLinks() {
  const fs::path path = Folder() / "hundred.urdf";
  if (fs::exists(path)) return path;
  const std::string stl =
      std::string(SWARMSIM_SOURCE_DIR) + "/worlds/models/simple_arm_description/meshes/tool.stl";
  std::string u =
      "<?xml version=\"1.0\"?>\n<robot name=\"hundred\">\n"
      "  <material name=\"orange\"><color rgba=\"0.95 0.45 0.1 1\"/></material>\n";
  for (int i = 0; i < 100; ++i) {
    const std::string n = std::to_string(i);
    u += "  <link name=\"l" + n +
         "\">\n"
         "    <inertial><origin xyz=\"0 0 0.02\"/><mass value=\"0.2\"/><inertia ixx=\"2e-4\" "
         "iyy=\"2e-4\" izz=\"1e-4\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>\n"
         "    <collision><origin xyz=\"0 0 0.02\"/><geometry><box size=\"0.03 0.03 0.04\"/>"
         "</geometry></collision>\n"
         "    <visual><origin xyz=\"0 0 0.02\"/><geometry><cylinder radius=\"0.015\" "
         "length=\"0.04\"/></geometry><material name=\"orange\"/></visual>\n";
    if (i % 10 == 9)
      u += "    <visual><geometry><mesh filename=\"" + stl + "\"/></geometry></visual>\n";
    u += "  </link>\n";
    if (i == 0) continue;
    const bool fixed = i % 4 == 0;
    u += "  <joint name=\"j" + n + "\" type=\"" + (fixed ? "fixed" : "revolute") +
         "\">"
         "<parent link=\"l" +
         std::to_string(i - 1) + "\"/><child link=\"l" + n +
         "\"/>"
         "<origin xyz=\"0 0 0.04\" rpy=\"0 0 0.3\"/>" +
         (fixed ? ""
                : "<axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"5\" "
                  "velocity=\"2\"/>") +
         "</joint>\n";
  }
  u += "</robot>\n";
  std::ofstream(path) << u;
  return path;
}

void BM_ImportHundredLinks(benchmark::State& state) {
  const fs::path path = HundredLinks();
  for (auto _ : state) {
    swarmsim::loader::UrdfImport robot =
        swarmsim::loader::ImportUrdf(path, "", path.string(), {}, nullptr);
    benchmark::DoNotOptimize(robot);
  }
}
BENCHMARK(BM_ImportHundredLinks)->Unit(benchmark::kMillisecond);

void LoadWorld(benchmark::State& state, const std::string& model, const std::string& packages) {
  swarmsim::ModuleRegistry registry;
  swarmsim::RegisterBuiltinModules(&registry);
  const fs::path world = Folder() / "world.yaml";
  std::ofstream(world) << "simulation: {physics: ode, time_step: 0.01}\npackage_path: [" +
                              packages + "]\nmodels: [{model: " + model +
                              ", position: [0, 0, 1]}]\n";
  for (auto _ : state) {
    swarmsim::LoadOptions options;
    swarmsim::LoadedWorld w = swarmsim::LoadWorld(world, options, registry);
    w.world->Start();  // builds the ODE bodies and joints
    benchmark::DoNotOptimize(w);
  }
}

void BM_LoadHundredLinkWorld(benchmark::State& state) {
  LoadWorld(state, HundredLinks().string(), ".");
}
BENCHMARK(BM_LoadHundredLinkWorld)->Unit(benchmark::kMillisecond);

void BM_LoadTiagoDual(benchmark::State& state) {
  const fs::path robot = fs::path(SWARMSIM_SOURCE_DIR) / ".." / "shared" / "urdf-corpus" / "tiago";
  const fs::path urdf =
      robot / "example-robot-data/robots/tiago_description/robots/tiago_dual.urdf";
  if (!fs::exists(urdf)) {
    state.SkipWithError("../shared/urdf-corpus is not here");
    return;
  }
  LoadWorld(state, fs::weakly_canonical(urdf).string(), fs::weakly_canonical(robot).string());
}
BENCHMARK(BM_LoadTiagoDual)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
