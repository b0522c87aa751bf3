// Light sensors (modules/light): what 8 light sensors per robot cost, for
// 1,000 and 10,000 robots and one or four lights.
//
// N robots at 1 robot per m^2 in a walled square arena (side sqrt(N) m),
// on a jittered grid with random headings: a cylinder body (r 0.085 m,
// 0.146 m high) with 8 light sensors round it (as a light_sensor_ring of 8,
// radius 0.085 m, 0.06 m up, fov 180 deg); lamps 0.5 m up, one at the
// centre or four at the quarter points. Kinematic physics and no scripts.
//
//   BM_Sense/N/lights/threads             the light module's sense phase
//                                         (occlusion by the walls on: the
//                                         world's line of sight)
//   BM_SenseNoOcclusion/N/lights/threads  the same with occlusion off
//   BM_SenseRobotOcclusion/...            robot_occlusion on too (every
//                                         other robot's body tested)
//   BM_SenseNoise/...                     occlusion on, Gaussian noise and a
//                                         failure probability
//
// per_robot is wall time per robot and step (target: <= 0.2 us with 8
// sensors and one light).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/light/light.h"

namespace swarmsim {
namespace {

struct Swarm {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  double lit_fraction = 0;  // sensors reading > 0 after the first step
};

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

enum Variant { kOcclusion, kNoOcclusion, kRobotOcclusion, kNoise };

std::unique_ptr<Swarm> MakeSwarm(int robots, int lights, int threads, Variant variant) {
  auto swarm = std::make_unique<Swarm>();
  RegisterBuiltinModules(&swarm->registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  swarm->world = std::make_unique<World>(settings, swarm->registry);
  Scene& scene = swarm->world->scene();
  ObjectType source_type, sensor_type;
  scene.FindType(light::kLightSourceTypeName, &source_type);
  scene.FindType(light::kLightSensorTypeName, &sensor_type);
  // Walls around [-side/2, side/2]^2, 0.1 m thick, 0.2 m high.
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots)));
  const double side = per_row, t = 0.1, h = 0.2, c = side / 2 + t / 2;
  scene.AddShape("wall_s", {}, {{0, -c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_n", {}, {{0, c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_w", {}, {{-c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  scene.AddShape("wall_e", {}, {{c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  for (int l = 0; l < lights; ++l) {
    const double q = lights == 1 ? 0 : side / 4;
    light::LightSourceRow lamp;
    scene.AddObject(source_type, "lamp", {}, {{l % 2 ? q : -q, l / 2 ? q : -q, 0.5}, {}}, &lamp);
  }
  light::LightSensorSettings s;
  s.occlusion = variant != kNoOcclusion;
  s.robot_occlusion = variant == kRobotOcclusion;
  if (variant == kNoise) {
    s.noise.gaussian = 0.01;
    s.noise.failure = 0.05;
  }
  light::LightSensorRow sensor;
  sensor.settings = Shared<light::LightSensorSettings>(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), yaw(-M_PI, M_PI);
  for (int i = 0; i < robots; ++i) {
    const double x = -side / 2 + 0.5 + i % per_row + jitter(rng);
    const double y = -side / 2 + 0.5 + i / per_row + jitter(rng);
    const std::string name = "bot#" + std::to_string(i);
    const ObjectId root = scene.AddShape(name, {}, {{x, y, 0.073}, Quat::FromYaw(yaw(rng))},
                                         Shape(ShapeKind::kCylinder, {0.085, 0, 0.146}));
    scene.MakeModelInstance(root, "bot", name);
    for (int k = 0; k < 8; ++k) {
      const double a = k * M_PI / 4;
      scene.AddObject(sensor_type, "light", root,
                      {{0.085 * std::cos(a), 0.085 * std::sin(a), -0.013}, Quat::FromYaw(a)},
                      &sensor);
    }
  }
  swarm->world->Start();
  swarm->world->Step();
  std::span<const uint32_t> owners;
  int lit = 0;
  const auto rows = light::Sensors(scene, &owners);
  for (const light::LightSensorRow& row : rows) lit += row.reading > 0;
  swarm->lit_fraction = rows.empty() ? 0 : double(lit) / rows.size();
  return swarm;
}

void Sense(benchmark::State& state, Variant variant) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), static_cast<int>(state.range(2)),
                         variant);
  Module* module = swarm->world->find_module("light");
  for (auto _ : state) module->Sense(swarm->world.get());
  state.counters["per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["lit_fraction"] = swarm->lit_fraction;
}

void BM_Sense(benchmark::State& state) { Sense(state, kOcclusion); }
void BM_SenseNoOcclusion(benchmark::State& state) { Sense(state, kNoOcclusion); }
void BM_SenseRobotOcclusion(benchmark::State& state) { Sense(state, kRobotOcclusion); }
void BM_SenseNoise(benchmark::State& state) { Sense(state, kNoise); }

void Args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"robots", "lights", "threads"});
  for (int threads : {1, 2}) b->Args({1000, 1, threads});
  b->Args({1000, 4, 1});
  b->Args({10000, 1, 1});
  b->Args({10000, 1, 2});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Sense)->Apply(Args);
BENCHMARK(BM_SenseNoOcclusion)->Apply(Args);
BENCHMARK(BM_SenseRobotOcclusion)->Args({1000, 1, 1})->Args({1000, 1, 2})->Apply([](auto* b) {
  b->ArgNames({"robots", "lights", "threads"});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
});
BENCHMARK(BM_SenseNoise)->Args({1000, 1, 1})->Args({10000, 1, 1})->Apply([](auto* b) {
  b->ArgNames({"robots", "lights", "threads"});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
});

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
