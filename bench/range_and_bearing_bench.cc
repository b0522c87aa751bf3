// Range-and-bearing boards (modules/range_and_bearing): the sense phase of
// 10,000 robots, each hearing about 10 others.
//
// N robots on a jittered grid (1.53 m apart: 0.43 robots per m^2, so
// about 10 others heard within a foot-bot board's 3 m) in a walled square arena
// with 40 interior walls (0.1 m thick, 4 m long, 0.3 m high) and random
// headings: a cylinder body (r 0.085 m, 0.146 m high) and a board 0.05 m
// above its centre, range 3 m, 10-byte payloads. Kinematic physics and no
// scripts.
//
//   BM_Sense/N/threads                the module's sense phase, occlusion by
//                                     walls on (target <= 1 us per robot-tick)
//   BM_SenseRobotOcclusion/N/threads  the same with robot occlusion on
//                                     (target <= 3 us)
//   BM_SenseNoOcclusion/N/threads     neither
//   BM_SenseNoisy/N/threads           walls, loss 0.1 + 0.2 (d/r)^2, range and
//                                     bearing noise, capacity 5 at random
//
// per_robot is wall time per robot and step; heard_per_board the readings
// per board after occlusion.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/range_and_bearing/range_and_bearing.h"

namespace swarmsim {
namespace {

using range_and_bearing::RangeAndBearingRow;
using range_and_bearing::RangeAndBearingSettings;

struct Swarm {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  ObjectType type{};
  size_t heard = 0;  // readings after the first step, over all boards
};

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

enum class Mode { kNone, kWalls, kRobots, kNoisy };

std::unique_ptr<Swarm> MakeSwarm(int robots, int threads, Mode mode) {
  auto swarm = std::make_unique<Swarm>();
  RegisterBuiltinModules(&swarm->registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  swarm->world = std::make_unique<World>(settings, swarm->registry);
  Scene& scene = swarm->world->scene();
  scene.FindType(range_and_bearing::kTypeName, &swarm->type);
  const double spacing = 1.53;
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots)));
  const double side = per_row * spacing, t = 0.1, h = 0.3, c = side / 2 + t / 2;
  scene.AddShape("wall_s", {}, {{0, -c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_n", {}, {{0, c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_w", {}, {{-c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  scene.AddShape("wall_e", {}, {{c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.4, 0.4), yaw(-M_PI, M_PI),
      where(-side / 2 + 2, side / 2 - 2);
  for (int i = 0; i < 40; ++i)
    scene.AddShape("inner", {}, {{where(rng), where(rng), h / 2}, Quat::FromYaw(yaw(rng))},
                   Shape(ShapeKind::kBox, {4, t, h}));
  RangeAndBearingSettings s;
  s.range = 3;
  s.payload_size = 10;
  s.occlusion = mode != Mode::kNone;
  s.robot_occlusion = mode == Mode::kRobots;
  if (mode == Mode::kNoisy) {
    s.loss_probability = 0.1;
    s.loss_at_range = 0.2;
    s.range_noise.gaussian = 0.02;
    s.bearing_noise.gaussian = 0.05;
    s.capacity = 5;
    s.capacity_order = range_and_bearing::CapacityOrder::kRandom;
  }
  const Shared<RangeAndBearingSettings> shared(s);
  for (int i = 0; i < robots; ++i) {
    const double x = -side / 2 + spacing * (0.5 + i % per_row) + jitter(rng);
    const double y = -side / 2 + spacing * (0.5 + i / per_row) + jitter(rng);
    const std::string name = "bot#" + std::to_string(i);
    const ObjectId root = scene.AddShape(name, {}, {{x, y, 0.073}, Quat::FromYaw(yaw(rng))},
                                         Shape(ShapeKind::kCylinder, {0.085, 0, 0.146}));
    scene.MakeModelInstance(root, "bot", name);
    RangeAndBearingRow row;
    row.settings = shared;
    row.data = {static_cast<uint8_t>(i), static_cast<uint8_t>(i >> 8)};
    scene.AddObject(swarm->type, "rab", root, {{0, 0, 0.05}, {}}, &row);
  }
  swarm->world->Start();
  swarm->world->Step();
  for (const RangeAndBearingRow& row : scene.rows<RangeAndBearingRow>(swarm->type).rows)
    swarm->heard += row.readings.size();
  return swarm;
}

void Sense(benchmark::State& state, Mode mode) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), mode);
  Module* module = swarm->world->find_module("range_and_bearing");
  for (auto _ : state) module->Sense(swarm->world.get());
  state.counters["per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["heard_per_board"] = double(swarm->heard) / robots;
}

void BM_Sense(benchmark::State& state) { Sense(state, Mode::kWalls); }
void BM_SenseRobotOcclusion(benchmark::State& state) { Sense(state, Mode::kRobots); }
void BM_SenseNoOcclusion(benchmark::State& state) { Sense(state, Mode::kNone); }
void BM_SenseNoisy(benchmark::State& state) { Sense(state, Mode::kNoisy); }

void Args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"robots", "threads"});
  for (int threads : {1, 2}) b->Args({10000, threads});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Sense)->Apply(Args);
BENCHMARK(BM_SenseRobotOcclusion)->Apply(Args);
BENCHMARK(BM_SenseNoOcclusion)->Apply(Args);
BENCHMARK(BM_SenseNoisy)->Apply(Args);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
