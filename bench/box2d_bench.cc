// One Box2D physics substep for swarms of 100, 1,000 and 10,000 wheeled
// robots (1 robot per m^2, all driving small circles inside a walled arena),
// through the backend (DynamicsBackend::Step with one substep, write-back
// included) and bare (box2d::TimeBareLoop: the same Box2D world and traction,
// no scene). Second argument: Box2D units per metre (1 = Box2D's own metres,
// 10 = the backend's default). Counter ns_per_robot_substep is what to
// compare; on a busy machine run with --benchmark_repetitions=5 and read the
// _min rows.
//
// BM_PhysicsPhase and BM_PoseUpdate time what World::Physics does per
// control step for foot-bot-like robots (body, two wheel joints with their
// wheels, a ring of 24 proximity sensors): the backend's 10 substeps with
// write-back, then the post-physics world pose update of every robot's
// subtree; BM_PoseUpdate times that update alone (counter
// ns_per_robot_tick). Compare BM_PhysicsPhase with BM_Box2dBareSubstep x 10.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/scene.h"
#include "modules/dynamics/box2d/box2d_backend.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim::box2d {
namespace {

constexpr double kDt = 0.01;  // s

// A footbot-like robot: cylinder body r 8.5 cm, wheels r 2.9 cm at +-7 cm,
// mirror-mounted, driving a circle of radius ~0.28 m (left 5, right 3 cm/s).
void AddRobot(Scene* scene, int index, double x, double y) {
  ShapeData body;
  body.kind = ShapeKind::kCylinder;
  body.size = {0.085, 0, 0.1};
  body.dynamic = true;
  body.mass = 1.6;
  const ObjectId root =
      scene->AddShape("robot", {}, {{x, y, 0.05}, Quat::FromYaw(0.1 * index)}, body);
  std::string name = "robot#";  // (not "robot#" + ...: GCC 12 -Wrestrict false positive)
  name += std::to_string(index);
  scene->MakeModelInstance(root, "robot", name);
  JointData motor;
  ShapeData wheel;
  wheel.kind = ShapeKind::kCylinder;
  wheel.size = {0.029, 0, 0.01};
  const double wheel_z = 0.029 - 0.05;
  const ObjectId left = scene->AddJoint(
      "leftMotor", root, {{0, 0.07, wheel_z}, Quat::FromAxisAngle({1, 0, 0}, -M_PI / 2)}, motor);
  const ObjectId right = scene->AddJoint(
      "rightMotor", root, {{0, -0.07, wheel_z}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)}, motor);
  scene->AddShape("leftWheel", left, {}, wheel);
  scene->AddShape("rightWheel", right, {}, wheel);
  scene->mutable_joint(left).target_velocity = 0.05 / 0.029;
  scene->mutable_joint(right).target_velocity = -0.03 / 0.029;
}

// The foot-bot's ring of 24 proximity sensors, rays outwards.
void AddProximityRing(Scene* scene, ObjectId body) {
  ProximitySensorData sensor;
  for (int i = 0; i < 24; ++i) {
    const double a = i * M_PI / 12;
    const Quat q_BS = Quat::FromYaw(a) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
    proximity::AddSensor(scene, "prox", body,
                         {{0.085 * std::cos(a), 0.085 * std::sin(a), -0.013}, q_BS}, sensor);
  }
}

// n robots on a square grid, 1 m apart, in an arena with four walls.
std::unique_ptr<Scene> MakeSwarm(int n, bool proximity_ring = false) {
  auto scene = std::make_unique<Scene>();
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double extent = side;  // m
  ShapeData wall;
  wall.kind = ShapeKind::kBox;
  for (int i = 0; i < 4; ++i) {
    const bool vertical = i < 2;
    const double offset = (i % 2 == 0 ? -0.05 : extent + 0.05);
    wall.size = vertical ? Vec3{0.1, extent + 0.2, 0.2} : Vec3{extent + 0.2, 0.1, 0.2};
    const Vec3 p = vertical ? Vec3{offset, extent / 2, 0.1} : Vec3{extent / 2, offset, 0.1};
    scene->AddShape("wall", {}, {p, {}}, wall);
  }
  for (int i = 0; i < n; ++i) {
    AddRobot(scene.get(), i, 0.5 + i % side, 0.5 + i / side);
    if (proximity_ring) AddProximityRing(scene.get(), scene->instances().back().root);
  }
  return scene;
}

Options WithScale(int64_t scale) {
  Options options;
  options.length_scale = static_cast<double>(scale);
  return options;
}

// Wall-clock time is what TimeBareLoop returns, so both benchmarks report it
// (manual time, counter ns_per_robot_substep). On a machine shared with
// other work, wall time includes time spent descheduled; the thread's CPU
// time (cpu_ns_per_robot_substep; for the bare loop it includes building
// the world, under 3% at these sizes) is the steadier figure. Take the min of
// repetitions.
double ThreadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void SetCounters(benchmark::State& state, double wall_s, double cpu_s, double robot_substeps) {
  const double per = robot_substeps > 0 ? 1e9 / robot_substeps : 0;
  state.counters["ns_per_robot_substep"] = wall_s * per;
  state.counters["cpu_ns_per_robot_substep"] = cpu_s * per;
}

// Runs `work` once per benchmark iteration as manual time; returns the wall
// and thread-CPU seconds spent in it.
struct Spent {
  double wall_s = 0, cpu_s = 0;
};
template <typename Work>
Spent TimeIterations(benchmark::State& state, Work work) {
  Spent spent;
  const double cpu_start = ThreadCpuSeconds();
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    work();
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(s);
    spent.wall_s += s;
  }
  spent.cpu_s = ThreadCpuSeconds() - cpu_start;
  return spent;
}

// ns per robot-tick (one control step of `n` robots per iteration).
void SetTickCounters(benchmark::State& state, const Spent& spent, int n) {
  const double ticks = static_cast<double>(n) * static_cast<double>(state.iterations());
  state.counters["ns_per_robot_tick"] = 1e9 * spent.wall_s / ticks;
  state.counters["cpu_ns_per_robot_tick"] = 1e9 * spent.cpu_s / ticks;
}

// The backend: one Step of one substep, with the scene write-back.
void BM_Box2dBackendSubstep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto scene = MakeSwarm(n);
  auto backend = MakeBackend(WithScale(state.range(1)));
  backend->Build(*scene, {});
  for (int i = 0; i < 100; ++i) backend->Step(scene.get(), kDt, 1);  // settle
  const Spent spent = TimeIterations(state, [&] { backend->Step(scene.get(), kDt, 1); });
  SetCounters(state, spent.wall_s, spent.cpu_s,
              static_cast<double>(n) * static_cast<double>(state.iterations()));
}

// Box2D alone (the `box2d-only` row): TimeBareLoop's stepping time only.
void BM_Box2dBareSubstep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int substeps = std::max(100, 2'000'000 / n);  // per iteration
  auto scene = MakeSwarm(n);
  const Options options = WithScale(state.range(1));
  double wall_s = 0;
  const double cpu_start = ThreadCpuSeconds();
  for (auto _ : state) {
    const double s = TimeBareLoop(*scene, kDt, 1, substeps, options);
    state.SetIterationTime(s);
    wall_s += s;
  }
  SetCounters(state, wall_s, ThreadCpuSeconds() - cpu_start,
              static_cast<double>(n) * substeps * static_cast<double>(state.iterations()));
}

// World::Physics's post-physics update: each robot's subtree, then the rest.
void UpdatePoses(Scene* scene) {
  for (int r = 0; r < static_cast<int>(scene->instances().size()); ++r) scene->UpdateWorldPoses(r);
  scene->UpdateSceneObjectPoses();
}

constexpr int kSubstepsPerTick = 10;

// One control step of the physics phase: 10 substeps, write-back, pose update.
void BM_PhysicsPhase(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto scene = MakeSwarm(n, /*proximity_ring=*/true);
  auto backend = MakeBackend();
  backend->Build(*scene, {});
  for (int i = 0; i < 10; ++i) {  // settle
    backend->Step(scene.get(), kDt, kSubstepsPerTick);
    UpdatePoses(scene.get());
  }
  const auto tick = [&] {
    backend->Step(scene.get(), kDt, kSubstepsPerTick);
    UpdatePoses(scene.get());
  };
  SetTickCounters(state, TimeIterations(state, tick), n);
}

// The post-physics pose update alone (bodies flagged as simulated, as after
// a backend step).
void BM_PoseUpdate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  auto scene = MakeSwarm(n, /*proximity_ring=*/true);
  auto backend = MakeBackend();
  backend->Build(*scene, {});
  backend->Step(scene.get(), kDt, kSubstepsPerTick);
  UpdatePoses(scene.get());
  std::vector<uint32_t> bodies;
  for (const ModelInstance& instance : scene->instances()) bodies.push_back(instance.root.index());
  const auto tick = [&] {
    for (uint32_t slot : bodies)
      scene->SetSimulatedState(slot, scene->world_pose_at(slot), scene->linear_velocity_at(slot),
                               scene->angular_velocity_at(slot));
    UpdatePoses(scene.get());
  };
  SetTickCounters(state, TimeIterations(state, tick), n);
}

double Min(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void SwarmArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : {100, 1000, 10000})
    for (int64_t scale : {1, 10}) b->Args({n, scale});
  b->ArgNames({"robots", "scale"});
  b->UseManualTime()->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", Min);
}

void RobotArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : {100, 1000, 10000}) b->Arg(n);
  b->ArgNames({"robots"});
  b->UseManualTime()->Unit(benchmark::kMicrosecond)->ComputeStatistics("min", Min);
}

BENCHMARK(BM_Box2dBackendSubstep)->Apply(SwarmArgs);
BENCHMARK(BM_Box2dBareSubstep)->Apply(SwarmArgs);
BENCHMARK(BM_PhysicsPhase)->Apply(RobotArgs);
BENCHMARK(BM_PoseUpdate)->Apply(RobotArgs);

}  // namespace
}  // namespace swarmsim::box2d

BENCHMARK_MAIN();
