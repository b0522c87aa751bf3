// The Lua host's hot paths: one robot's control phase (a diffusion
// controller: 24 proximity reads, 2 joint writes), an empty callback
// dispatch, and the memory a robot's Lua state holds.
//
//   build/bench/lua_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "framework/scene.h"
#include "framework/script_host.h"
#include "framework/world.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

// `path` relative to the source tree (found from this file's location).
std::shared_ptr<const ScriptSource> LoadScript(const std::string& path) {
  std::ifstream in(std::filesystem::path(__FILE__).parent_path().parent_path() / path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream code;
  code << in.rdbuf();
  return std::make_shared<const ScriptSource>(ScriptSource{path, code.str()});
}

// A foot-bot as scripts/diffusion.lua expects it: a root shape `body` with
// the script, two velocity-mode wheel joints and 24 proximity sensors
// `prox` around it, counter-clockwise from the front. `detections` of the
// sensors see something.
ObjectId AddFootbot(Scene* scene, std::shared_ptr<const ScriptSource> script, double x,
                    int detections) {
  ShapeData body_shape;
  body_shape.kind = ShapeKind::kCylinder;
  body_shape.size = {0.085, 0, 0.15};
  const ObjectId body = scene->AddShape("body", {}, {{x, 0, 0.075}, {}}, body_shape);
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {0.029, 0, 0.02};
  JointData motor;
  motor.settings.Edit().mode = JointMode::kVelocity;
  for (const char* side : {"left", "right"}) {
    const double y = side[0] == 'l' ? 0.07 : -0.07;
    const ObjectId joint =
        scene->AddJoint(std::string(side) + "Motor", body,
                        {{0, y, -0.046}, Quat::FromRollPitchYaw(M_PI / 2, 0, 0)}, motor);
    scene->AddShape(std::string(side) + "Wheel", joint, {}, wheel);
  }
  for (int i = 0; i < 24; ++i) {
    const double angle = 2 * M_PI * i / 24;
    ProximitySensorData sensor;
    sensor.settings.Edit().range = 0.1;
    if (i < detections) {
      sensor.detected = true;
      sensor.distance = 0.05;
    }
    proximity::AddSensor(scene, "prox", body,
                         {{0.085 * std::cos(angle), 0.085 * std::sin(angle), 0},
                          Quat::FromRollPitchYaw(0, M_PI / 2, angle)},
                         sensor);
  }
  scene->MakeModelInstance(body, "footbot", "footbot#" + std::to_string(scene->instances().size()));
  scene->AttachScript(body, std::move(script));
  return body;
}

// Bytes malloc has handed out and not taken back, small and mmapped blocks.
size_t HeapInUse() {
  const struct mallinfo2 info = mallinfo2();
  return info.uordblks + info.hblkhd;
}

struct Bench {
  explicit Bench(int threads = 1) : registry(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.threads = threads;
    world = std::make_unique<World>(settings, registry);
    world->set_log_sink([](std::string_view) {});
  }
  ModuleRegistry registry;
  std::unique_ptr<World> world;
};

void RunControl(benchmark::State& state, Bench* b) {
  ScriptHost& host = *b->world->scripts();
  RobotRuntime& runtime = b->world->runtime(0);
  for (auto _ : state) {
    host.RunInstance(0, ScriptPass::kAll);
    runtime.deferred.clear();
  }
  state.SetItemsProcessed(state.iterations());
}

// One robot's control phase with the diffusion controller; Arg = sensors
// that detect something (0: the no-allocation path; 24: every read returns
// a table).
void BM_DiffusionStep(benchmark::State& state) {
  Bench b;
  AddFootbot(&b.world->scene(), LoadScript("scripts/diffusion.lua"), 0,
             static_cast<int>(state.range(0)));
  b.world->Start();
  RunControl(state, &b);
}
BENCHMARK(BM_DiffusionStep)->Arg(0)->Arg(3)->Arg(24);

// Dispatch cost alone: sysCall_sensing and sysCall_actuation that do nothing.
void BM_EmptyCallbackDispatch(benchmark::State& state) {
  Bench b;
  AddFootbot(&b.world->scene(),
             std::make_shared<const ScriptSource>(ScriptSource{
                 "empty.lua", "function sysCall_sensing() end function sysCall_actuation() end"}),
             0, 0);
  b.world->Start();
  RunControl(state, &b);
}
BENCHMARK(BM_EmptyCallbackDispatch);

// RunInstance over Arg robots in turn, nothing else: one robot's control
// cost when its Lua heap is not in cache.
void BM_ControlSweep(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  Bench b;
  auto script = LoadScript("scripts/diffusion.lua");
  for (int r = 0; r < robots; ++r) AddFootbot(&b.world->scene(), script, 0.3 * r, 3);
  b.world->Start();
  ScriptHost& host = *b.world->scripts();
  int r = 0;
  for (auto _ : state) {
    host.RunInstance(r, ScriptPass::kAll);
    r = r + 1 == robots ? 0 : r + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ControlSweep)->Arg(1)->Arg(100)->Arg(1000)->Arg(10000);

// A whole step of Arg robots running the diffusion controller (3 sensors
// detecting), null physics and proximity: the control phase at scale, with
// the cache misses one robot alone does not see. Second arg: threads.
void BM_SwarmStep(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  Bench b(static_cast<int>(state.range(1)));
  auto script = LoadScript("scripts/diffusion.lua");
  for (int r = 0; r < robots; ++r) AddFootbot(&b.world->scene(), script, 0.3 * r, 3);
  b.world->Start();
  const double control_before = b.world->phase_times()[static_cast<size_t>(Phase::kControl)];
  for (auto _ : state) b.world->Step();
  // Seconds per robot and step: the whole step, and the control phase alone.
  state.counters["step_per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["control_per_robot"] =
      (b.world->phase_times()[static_cast<size_t>(Phase::kControl)] - control_before) /
      (static_cast<double>(state.iterations()) * robots);
}
BENCHMARK(BM_SwarmStep)
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({10000, 2})
    ->Unit(benchmark::kMillisecond);

// Memory of Arg robots running the diffusion controller, after 20 steps
// with 3 sensors detecting: Lua's own count (lua_gc LUA_GCCOUNT) and what
// malloc handed out for the whole robot (scene rows, runtime, Lua state and
// allocator overhead). Also the wall time of World::Start (2 threads).
void BM_RobotMemory(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const size_t heap_before = HeapInUse();
    Bench b(2);
    auto script = LoadScript("scripts/diffusion.lua");
    for (int r = 0; r < robots; ++r) AddFootbot(&b.world->scene(), script, 0.3 * r, 3);
    const size_t heap_scene = HeapInUse();
    const auto start = std::chrono::steady_clock::now();
    b.world->Start();
    state.counters["start_ms"] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    state.counters["lua_gccount_B_per_robot_at_start"] =
        static_cast<double>(b.world->script_memory_bytes()) / robots;
    for (int i = 0; i < 20; ++i) b.world->Step();
    const size_t heap_after = HeapInUse();
    state.counters["lua_gccount_B_per_robot"] =
        static_cast<double>(b.world->script_memory_bytes()) / robots;
    state.counters["scene_heap_B_per_robot"] =
        static_cast<double>(heap_scene - heap_before) / robots;
    state.counters["total_heap_B_per_robot"] =
        static_cast<double>(heap_after - heap_before) / robots;
  }
}
BENCHMARK(BM_RobotMemory)->Arg(10000)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
