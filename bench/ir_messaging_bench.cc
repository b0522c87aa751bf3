// IR messaging (modules/ir_messaging): the sense phase of a Kilobot swarm.
//
// N Kilobot-sized robots (dummy roots) on a square lattice 5 cm apart,
// jittered by up to 5 mm, each with a transceiver (the Kilobot's defaults:
// 10 cm, 12-byte messages of 4 ms, carrier sense, collisions, 2 mm noise),
// so that about 12 others are within range. Each step one robot in 16
// queues a 12-byte message (each robot every 16th step, at a random phase:
// every 0.5 s at 1/32 s steps, as kilolib sends), as a controller would
// before the sense phase. Kinematic physics, no scripts.
//
//   BM_Sense/N/threads  the module's sense phase alone (queuing included)
//   BM_Step/N/threads   the whole world step (sense, control with nothing
//                       to run, actuate, kinematic physics, record)
//
// per_robot is wall time per robot and step; heard_per_robot the messages
// a robot hears per step, sent_fraction the share of queued messages that
// went out (the rest deferred: carrier sense).
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/ir_messaging/ir_messaging.h"

namespace swarmsim {
namespace {

using ir_messaging::IrSettings;
using ir_messaging::IrTransceiverRow;

struct Swarm {
  ModuleRegistry registry;
  std::unique_ptr<World> world;
  ObjectType type{};
  int64_t step = 0;
  std::vector<std::vector<uint32_t>> by_phase;  // the robots that queue at step % 16
  size_t heard = 0, queued = 0, sent = 0;
  Rows<IrTransceiverRow>& rows() { return world->scene().rows<IrTransceiverRow>(type); }
  // One robot in 16 queues its message.
  void Queue() {
    Rows<IrTransceiverRow>& r = rows();
    for (uint32_t i : by_phase[static_cast<size_t>(step % 16)]) {
      r.rows[i].outgoing.assign(12, static_cast<uint8_t>(i));
      r.rows[i].queued = true;
    }
    ++step;
  }
  void Count() {
    for (const IrTransceiverRow& row : rows().rows) {
      heard += row.inbox.size();
      sent += row.sent ? 1 : 0;
    }
  }
};

std::unique_ptr<Swarm> MakeSwarm(int robots, int threads) {
  auto swarm = std::make_unique<Swarm>();
  RegisterBuiltinModules(&swarm->registry);
  WorldSettings settings;
  settings.physics = "kinematic";
  settings.threads = threads;
  settings.time_step = 1.0 / 32;
  swarm->world = std::make_unique<World>(settings, swarm->registry);
  Scene& scene = swarm->world->scene();
  scene.FindType(ir_messaging::kTypeName, &swarm->type);
  const double spacing = 0.05;
  const int per_row = static_cast<int>(std::ceil(std::sqrt(robots)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  const Shared<IrSettings> shared(IrSettings{});
  swarm->by_phase.resize(16);
  for (int i = 0; i < robots; ++i) {
    swarm->by_phase[rng() % 16].push_back(static_cast<uint32_t>(i));
    const double x = spacing * (i % per_row) + jitter(rng);
    const double y = spacing * (i / per_row) + jitter(rng);
    const std::string name = "bot#" + std::to_string(i);
    const ObjectId root = scene.AddDummy(name, {}, {{x, y, 0.017}, {}});
    scene.MakeModelInstance(root, "bot", name);
    IrTransceiverRow row;
    row.settings = shared;
    scene.AddObject(swarm->type, "ir", root, {{0, 0, -0.017}, {}}, &row);
  }
  swarm->world->Start();
  // Counts over 16 steps: every robot queues once.
  for (int i = 0; i < 16; ++i) {
    swarm->Queue();
    swarm->world->Step();
    swarm->Count();
  }
  swarm->queued = static_cast<size_t>(robots);
  return swarm;
}

void Report(benchmark::State& state, const Swarm& swarm, int robots) {
  state.counters["per_robot"] = benchmark::Counter(
      robots, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["heard_per_robot"] = double(swarm.heard) / (16.0 * robots);
  state.counters["sent_fraction"] = double(swarm.sent) / double(swarm.queued);
}

void BM_Sense(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)));
  Module* module = swarm->world->find_module("ir_messaging");
  for (auto _ : state) {
    swarm->Queue();
    module->Sense(swarm->world.get());
  }
  Report(state, *swarm, robots);
}

void BM_Step(benchmark::State& state) {
  const int robots = static_cast<int>(state.range(0));
  auto swarm = MakeSwarm(robots, static_cast<int>(state.range(1)));
  for (auto _ : state) {
    swarm->Queue();
    swarm->world->Step();
  }
  Report(state, *swarm, robots);
}

void Args(benchmark::internal::Benchmark* b) {
  b->ArgNames({"robots", "threads"});
  for (int robots : {1000, 10000})
    for (int threads : {1, 2}) b->Args({robots, threads});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Sense)->Apply(Args);
BENCHMARK(BM_Step)->Apply(Args);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
