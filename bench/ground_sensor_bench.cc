// Ground sensors (modules/ground_sensor): what N robots with 4 ground
// sensors each (the foot-bot's motor ground sensors) cost a step.
//
// N robots at 1 robot per m^2 on a jittered grid with random headings, over
// a floor (modules/floor) of 2 cm pixels covering the square, with a nest
// and a gradient drawn on it; kinematic physics and no scripts.
//
//   BM_Sense/N/threads        the ground sensor module's sense phase alone
//   BM_SenseNoisy/N/threads   the same with Gaussian noise and a failure
//                             probability on every sensor (two streams' draws)
//   BM_Step, BM_StepWithout   a whole World::Step with and without the sensors
//
// per_robot is wall time per robot and step (target: <= 0.2 us for 4 points).
// (Wall time: the 2-thread rows run the phase on both cores.)
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/floor/floor.h"
#include "modules/ground_sensor/ground_sensor.h"

namespace swarmsim {
namespace {

struct Swarm {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
};

std::unique_ptr<Swarm> MakeSwarm(int robots, int threads, bool sensors, bool noise) {
  auto swarm = std::make_unique<Swarm>();
  RegisterBuiltinModules(&swarm->registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  swarm->world = std::make_unique<World>(settings, swarm->registry);
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots)));
  const double side = per_row;
  // The floor: 2 cm pixels over the square, a black nest and a grey ramp.
  floors::FloorSettings floor;
  floor.resolution = 0.02;
  floor.min_x = floor.min_y = -side / 2;
  floor.max_x = floor.max_y = side / 2;
  floors::FloorShape nest;
  nest.kind = floors::FloorShape::Kind::kCircle;
  nest.radius = side / 4;
  floors::FloorShape ramp;
  ramp.kind = floors::FloorShape::Kind::kLinearGradient;
  ramp.a = {-side / 2, 0, 0};
  ramp.b = {side / 2, 0, 0};
  ramp.color2 = {1, 1, 1};
  floor.shapes = {ramp, nest};
  swarm->world->AddModule("floor", &floor);
  Scene& scene = swarm->world->scene();
  ObjectType ground_type;
  ground_sensor::FindSensorType(scene, &ground_type);
  ground_sensor::GroundSensorRow row;
  if (noise) {
    row.settings.Edit().noise.gaussian = 0.02;
    row.settings.Edit().noise.failure = 0.01;
  }
  const double points[4][2] = {
      {0.063, 0.0116}, {-0.063, 0.0116}, {-0.063, -0.0116}, {0.063, -0.0116}};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), yaw(-M_PI, M_PI);
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.size = {0.085, 0, 0.146};
  for (int i = 0; i < robots; ++i) {
    const double x = -side / 2 + 0.5 + i % per_row + jitter(rng);
    const double y = -side / 2 + 0.5 + i / per_row + jitter(rng);
    const std::string name = "bot#" + std::to_string(i);
    const ObjectId root = scene.AddShape(name, {}, {{x, y, 0.073}, Quat::FromYaw(yaw(rng))}, body);
    scene.MakeModelInstance(root, "bot", name);
    if (!sensors) continue;
    for (const auto& p : points)
      scene.AddObject(ground_type, "ground", root, {{p[0], p[1], -0.073}, {}}, &row);
  }
  swarm->world->Start();
  swarm->world->Step();
  return swarm;
}

void SetCounters(benchmark::State& state, int robots) {
  state.counters["per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void Sense(benchmark::State& state, bool noise) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), true, noise);
  Module* module = swarm->world->find_module("ground_sensor");
  for (auto _ : state) module->Sense(swarm->world.get());
  SetCounters(state, robots);
}
void BM_Sense(benchmark::State& state) { Sense(state, false); }
void BM_SenseNoisy(benchmark::State& state) { Sense(state, true); }

void BM_Step(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), true, false);
  for (auto _ : state) swarm->world->Step();
  SetCounters(state, robots);
}

void BM_StepWithout(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), false, false);
  for (auto _ : state) swarm->world->Step();
  SetCounters(state, robots);
}

void Args(benchmark::internal::Benchmark* b) {
  for (const int robots : {1000, 10000})
    for (const int threads : {1, 2}) b->Args({robots, threads});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

BENCHMARK(BM_Sense)->Apply(Args);
BENCHMARK(BM_SenseNoisy)->Apply(Args);
BENCHMARK(BM_Step)->Apply(Args);
BENCHMARK(BM_StepWithout)->Apply(Args);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
