// Blob cameras (modules/blobs): what 1,000 robots each with one LED and one
// omnidirectional blob camera add to a step.
//
// N robots at 1 robot per m^2 in a walled square arena (side sqrt(N) m),
// on a jittered grid with random headings: a cylinder body (r 0.085 m,
// 0.146 m high), an LED on top (0.156 m up) and a camera 0.2 m up, range
// 1 m, occlusion on (about 3 LEDs within 1 m of each camera). Kinematic
// physics and no scripts, so the step is the sensing and little else.
//
//   BM_Step/N/threads          a whole World::Step with LEDs and cameras
//   BM_StepWithout/N/threads   the same robots without LEDs and cameras
//   BM_Sense/N/threads         the blob module's sense phase alone
//   BM_SenseNoOcclusion/...    the same with occlusion off
//
// per_robot is wall time per robot and step; BM_Step minus BM_StepWithout
// is what the cameras add per robot-tick (target: <= 2 us).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"

namespace swarmsim {
namespace {

struct Swarm {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  size_t blobs = 0;  // blobs seen in the first step, over all cameras
};

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

std::unique_ptr<Swarm> MakeSwarm(int robots, int threads, bool cameras, bool occlusion) {
  auto swarm = std::make_unique<Swarm>();
  RegisterBuiltinModules(&swarm->registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  swarm->world = std::make_unique<World>(settings, swarm->registry);
  Scene& scene = swarm->world->scene();
  ObjectType led_type, camera_type;
  scene.FindType(kLedTypeName, &led_type);
  scene.FindType(kBlobCameraTypeName, &camera_type);
  // Walls around [-side/2, side/2]^2, 0.1 m thick, 0.2 m high.
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots)));
  const double side = per_row, t = 0.1, h = 0.2, c = side / 2 + t / 2;
  scene.AddShape("wall_s", {}, {{0, -c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_n", {}, {{0, c, h / 2}, {}}, Shape(ShapeKind::kBox, {side + 2 * t, t, h}));
  scene.AddShape("wall_w", {}, {{-c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  scene.AddShape("wall_e", {}, {{c, 0, h / 2}, {}}, Shape(ShapeKind::kBox, {t, side + 2 * t, h}));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), yaw(-M_PI, M_PI);
  const Vec3 colors[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < robots; ++i) {
    const double x = -side / 2 + 0.5 + i % per_row + jitter(rng);
    const double y = -side / 2 + 0.5 + i / per_row + jitter(rng);
    const std::string name = "bot#" + std::to_string(i);
    const ObjectId root = scene.AddShape(name, {}, {{x, y, 0.073}, Quat::FromYaw(yaw(rng))},
                                         Shape(ShapeKind::kCylinder, {0.085, 0, 0.146}));
    scene.MakeModelInstance(root, "bot", name);
    if (!cameras) continue;
    LedRow led;
    led.color = colors[i % 3];
    scene.AddObject(led_type, "led", root, {{0, 0, 0.083}, {}}, &led);
    BlobCameraRow camera;
    camera.range = 1;
    camera.occlusion = occlusion;
    scene.AddObject(camera_type, "camera", root, {{0, 0, 0.127}, {}}, &camera);
  }
  swarm->world->Start();
  swarm->world->Step();
  if (cameras)
    for (const BlobCameraRow& row :
         static_cast<const Rows<BlobCameraRow>&>(*scene.rows(camera_type)).rows)
      swarm->blobs += row.blobs.size();
  return swarm;
}

void SetCounters(benchmark::State& state, const Swarm& swarm, int robots) {
  state.counters["per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["blobs_per_camera"] = double(swarm.blobs) / robots;
}

void BM_Step(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), true, true);
  for (auto _ : state) swarm->world->Step();
  SetCounters(state, *swarm, robots);
}

void BM_StepWithout(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), false, true);
  for (auto _ : state) swarm->world->Step();
  SetCounters(state, *swarm, robots);
}

void Sense(benchmark::State& state, bool occlusion) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)), true, occlusion);
  Module* module = swarm->world->find_module("blobs");
  for (auto _ : state) module->Sense(swarm->world.get());
  SetCounters(state, *swarm, robots);
}

void BM_Sense(benchmark::State& state) { Sense(state, true); }
void BM_SenseNoOcclusion(benchmark::State& state) { Sense(state, false); }

void Args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"robots", "threads"});
  for (int threads : {1, 2}) b->Args({1000, threads});
  b->Args({10000, 2});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Step)->Apply(Args);
BENCHMARK(BM_StepWithout)->Apply(Args);
BENCHMARK(BM_Sense)->Apply(Args);
BENCHMARK(BM_SenseNoOcclusion)->Apply(Args);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
