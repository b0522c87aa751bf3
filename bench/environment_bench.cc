// The cost of an environment map (worlds/README.md, `environment:`): the
// shared laser-scanned map geb079.bt (143,729 occupied voxels of 0.08 m)
// read, indexed for the proximity sensors and merged for physics.
//
//   BM_ReadOctomap     the file into an EnvironmentMap (checks + library + boxes)
//   BM_IndexMap/res    the proximity module's Build with the map alone, at
//                      octree resolution res mm (80: the map's own)
//   BM_IndexMapAsShapes/res  the same voxels as static box shapes (the
//                      generic shape path), for comparison
//   BM_MergeBand2D/3D  the voxels at foot-bot height (0.001..0.145 m) merged
//                      into rectangles (Box2D) / boxes (ODE); counters give
//                      the counts
//
// The map is looked up in $SWARMSIM_MAPS_DIR, then /work/shared/maps; without
// it every benchmark is skipped. A whole world (load + first step of 100
// robots): `time build/swarmsim run worlds/octomap_corridor.yaml --set
// robots=100 --steps 1 --quiet`; its steps against an arena's: `swarmsim
// bench --world ...` (README.md).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "framework/scene.h"
#include "modules/environment/octomap_map.h"
#include "modules/environment/voxel_merge.h"
#include "modules/proximity/proximity.h"

namespace swarmsim {
namespace {

std::string MapPath() {
  const char* dir = std::getenv("SWARMSIM_MAPS_DIR");
  const std::filesystem::path p =
      std::filesystem::path(dir ? dir : "/work/shared/maps") / "geb079.bt";
  return std::filesystem::is_regular_file(p) ? p.string() : "";
}

const EnvironmentMap* Map() {
  static const std::unique_ptr<EnvironmentMap> map = [] {
    const std::string path = MapPath();
    return path.empty()
               ? nullptr
               : std::make_unique<EnvironmentMap>(environment::ReadOctomap(path, "geb079.bt", {}));
  }();
  return map.get();
}

void BM_ReadOctomap(benchmark::State& state) {
  const std::string path = MapPath();
  if (path.empty()) return state.SkipWithError("geb079.bt not found (SWARMSIM_MAPS_DIR)");
  size_t boxes = 0;
  for (auto _ : state) boxes = environment::ReadOctomap(path, "geb079.bt", {}).boxes.size();
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK(BM_ReadOctomap)->Unit(benchmark::kMillisecond);

void BM_IndexMap(benchmark::State& state) {
  if (Map() == nullptr) return state.SkipWithError("geb079.bt not found (SWARMSIM_MAPS_DIR)");
  Scene scene;
  scene.set_environment(std::make_shared<const EnvironmentMap>(*Map()));
  ProximitySettings settings;
  settings.octree_resolution = static_cast<double>(state.range(0)) / 1000;
  for (auto _ : state) {
    auto backend = proximity::MakeBackend();
    backend->Build(scene, settings);
    benchmark::DoNotOptimize(backend.get());
  }
}
BENCHMARK(BM_IndexMap)->Arg(80)->Arg(50)->Unit(benchmark::kMillisecond);

// For comparison: the same voxels as 143,729 static box shapes of a scene,
// through the generic shape path (each shape's voxels tested one by one,
// grown by a margin): what the map would cost without its own path.
void BM_IndexMapAsShapes(benchmark::State& state) {
  if (Map() == nullptr) return state.SkipWithError("geb079.bt not found (SWARMSIM_MAPS_DIR)");
  Scene scene;
  ShapeData box;
  box.kind = ShapeKind::kBox;
  for (const EnvironmentBox& b : Map()->boxes) {
    box.size = b.hi - b.lo;
    scene.AddShape("voxel", {}, {(b.lo + b.hi) * 0.5, {}}, box);
  }
  scene.UpdateWorldPoses();
  ProximitySettings settings;
  settings.octree_resolution = static_cast<double>(state.range(0)) / 1000;
  for (auto _ : state) {
    auto backend = proximity::MakeBackend();
    backend->Build(scene, settings);
    benchmark::DoNotOptimize(backend.get());
  }
}
BENCHMARK(BM_IndexMapAsShapes)->Arg(80)->Arg(50)->Unit(benchmark::kMillisecond);

void BM_MergeBand(benchmark::State& state, bool planar) {
  if (Map() == nullptr) return state.SkipWithError("geb079.bt not found (SWARMSIM_MAPS_DIR)");
  size_t boxes = 0;
  for (auto _ : state)
    boxes = (planar ? environment::MergeBand2D(*Map(), 0.001, 0.145)
                    : environment::MergeBand3D(*Map(), 0.001, 0.145))
                .size();
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK_CAPTURE(BM_MergeBand, 2D, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MergeBand, 3D, false)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
