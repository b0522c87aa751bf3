// Mills cutting the environment map (modules/mill/map_cut.h): one step of
// one drill on a floor map of N octree leaves (index built, cut, new map
// made), and the cost of a mill that is not near the map.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "modules/mill/map_cut.h"

namespace swarmsim::mill {
namespace {

// A floor of side x side leaves of 0.08 m (8 voxels of 0.01 m a side).
EnvironmentMap Floor(int side) {
  EnvironmentMap map;
  map.resolution = 0.01;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x)
      map.boxes.push_back({{x * 0.08, y * 0.08, -0.08}, {x * 0.08 + 0.08, y * 0.08 + 0.08, 0}});
  map.lo = {0, 0, -0.08};
  map.hi = {side * 0.08, side * 0.08, 0};
  return map;
}

Volume Drill() {
  Volume v;
  v.kind = VolumeKind::kCylinder;
  v.radius = 0.02;
  v.range = 0.05;
  return v;
}

// One step that cuts: the drill 3 cm into the floor's middle.
void BM_MapCutStep(benchmark::State& state) {
  const int side = static_cast<int>(state.range(0));
  const EnvironmentMap map = Floor(side);
  const Pose X_WM{{side * 0.04 + 0.013, side * 0.04 + 0.027, -0.03}, {}};
  for (auto _ : state) {
    MapCutter cutter;  // a new map each step: the index is built each time
    benchmark::DoNotOptimize(cutter.Cut(map, Drill(), X_WM));
    benchmark::DoNotOptimize(cutter.Finish(map));
  }
  state.counters["boxes"] = static_cast<double>(map.boxes.size());
}
BENCHMARK(BM_MapCutStep)->Arg(32)->Arg(100)->Arg(316)->Unit(benchmark::kMicrosecond);

// The same drill above the map's bounds: what a step costs a mill that is
// not near the map.
void BM_MapMillNotNear(benchmark::State& state) {
  const EnvironmentMap map = Floor(316);
  MapCutter cutter;
  const Pose X_WM{{12.6, 12.6, 0.5}, {}};
  for (auto _ : state) benchmark::DoNotOptimize(cutter.Cut(map, Drill(), X_WM));
}
BENCHMARK(BM_MapMillNotNear);

// The index alone (what another step that cuts the same map pays).
void BM_MapIndexQuery(benchmark::State& state) {
  const EnvironmentMap map = Floor(316);
  MapIndex index;
  index.Build(map);
  std::vector<uint32_t> hits;
  for (auto _ : state) {
    index.Query({12.6, 12.6, -0.05}, {12.65, 12.65, 0}, &hits);
    benchmark::DoNotOptimize(hits.data());
  }
}
BENCHMARK(BM_MapIndexQuery);

}  // namespace
}  // namespace swarmsim::mill

BENCHMARK_MAIN();
