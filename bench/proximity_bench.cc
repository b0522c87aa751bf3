// Proximity sensing cost per robot as the swarm grows at constant density.
//
// N robots at 1 robot per m^2 in a walled square arena (side sqrt(N) m,
// centred on the origin), on a jittered grid so that some robots see a
// neighbour and some see a wall.
// Each robot: an upright cylinder body (r = 0.085 m) and 24 ray sensors on a
// ring of radius 0.085 m at height 0.06 m, range 0.1 m, pointing radially out.
//
//   BM_SenseRobot     one robot's 24-ray read (SenseInstance), cycling over all robots
//   BM_SenseNearWall  the same, over the robots within reach of a wall only
//   BM_SenseAlone     the same, over the robots with nothing within reach (the early-out)
//   ..._CastAll       the same three with the early-out off: every ray cast
//   BM_Update         the per-step grid rebuild, reported per robot
//   BM_Build          indexing the walls into the octree (once per run)
//   BM_GridBuild      SpatialGrid::Build alone, per item (1 item per m^2)
//   BM_GridQuery      a 1 m circle query (range-limited messaging), per query
//
// per_ray / per_robot are wall time per ray / per robot; they should stay
// flat as N grows.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/proximity.h"

namespace swarmsim {
namespace {

constexpr int kRaysPerRobot = 24;
constexpr double kBodyRadius = 0.085;
constexpr double kRange = 0.1;

struct Swarm {
  Scene scene;
  std::unique_ptr<ProximityBackend> backend;
  std::unique_ptr<ProximityBackend> cast_all;  // the early-out off
  std::vector<int> near_wall;                  // instances whose rays may reach a wall
  std::vector<int> alone;  // instances with no wall and no other robot within reach
  int robots = 0;
};

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

// Walls around [-side/2, side/2]^2, 0.1 m thick, 0.2 m high.
void AddWalls(Scene* scene, double side) {
  const double t = 0.1, h = 0.2, c = side / 2 + t / 2;
  const ShapeData along_x = Shape(ShapeKind::kBox, {side + 2 * t, t, h});
  const ShapeData along_y = Shape(ShapeKind::kBox, {t, side + 2 * t, h});
  scene->AddShape("wall_s", {}, {{0, -c, h / 2}, {}}, along_x);
  scene->AddShape("wall_n", {}, {{0, c, h / 2}, {}}, along_x);
  scene->AddShape("wall_w", {}, {{-c, 0, h / 2}, {}}, along_y);
  scene->AddShape("wall_e", {}, {{c, 0, h / 2}, {}}, along_y);
}

void AddRobot(Scene* scene, const Pose& X_WR, int index) {
  const ObjectId root = scene->AddDummy("bot", {}, X_WR);
  scene->AddShape("body", root, {{0, 0, 0.06}, {}},
                  Shape(ShapeKind::kCylinder, {kBodyRadius, 0, 0.12}));
  ProximitySensorData ray;
  ray.settings.Edit().range = kRange;
  for (int k = 0; k < kRaysPerRobot; ++k) {
    const double a = 2 * M_PI * k / kRaysPerRobot;
    // z axis radially out: turn z onto x, then yaw by a.
    const Quat q = Quat::FromYaw(a) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
    proximity::AddSensor(scene, "ir", root,
                         {{kBodyRadius * std::cos(a), kBodyRadius * std::sin(a), 0.06}, q}, ray);
  }
  scene->MakeModelInstance(root, "bot", "bot#" + std::to_string(index));
}

// Built once per N and kept for all the benchmarks of that N.
Swarm& GetSwarm(int n) {
  static std::map<int, std::unique_ptr<Swarm>> swarms;
  auto& slot = swarms[n];
  if (slot) return *slot;
  slot = std::make_unique<Swarm>();
  Swarm& swarm = *slot;
  const double side = std::sqrt(double(n));
  const int per_row = static_cast<int>(std::ceil(side));
  const double cell = side / per_row;
  AddWalls(&swarm.scene, side);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.4 * cell, 0.4 * cell), yaw(-M_PI, M_PI);
  const double reach = kBodyRadius + kRange;
  std::vector<std::pair<double, double>> centres;
  for (int i = 0; i < n; ++i) {
    const double x = (i % per_row + 0.5) * cell + jitter(rng);  // from the arena's corner
    const double y = (i / per_row + 0.5) * cell + jitter(rng);
    AddRobot(&swarm.scene, {{x - side / 2, y - side / 2, 0}, Quat::FromYaw(yaw(rng))}, i);
    if (std::min({x, y, side - x, side - y}) <= reach) swarm.near_wall.push_back(i);
    centres.emplace_back(x, y);
  }
  // Alone: farther than reach + a body radius (with room) from walls and robots.
  const double alone = reach + kBodyRadius + 0.05;
  for (int i = 0; i < n; ++i) {
    const auto [x, y] = centres[i];
    bool near = std::min({x, y, side - x, side - y}) <= alone;
    for (int j = 0; j < n && !near; ++j)
      near = j != i && std::hypot(centres[j].first - x, centres[j].second - y) <= alone;
    if (!near) swarm.alone.push_back(i);
  }
  swarm.robots = n;
  swarm.scene.UpdateWorldPoses();
  swarm.backend = proximity::MakeBackend();
  swarm.backend->Build(swarm.scene, ProximitySettings{});
  swarm.backend->Update(swarm.scene);
  swarm.cast_all = proximity::MakeBackend({.early_out = false});
  swarm.cast_all->Build(swarm.scene, ProximitySettings{});
  swarm.cast_all->Update(swarm.scene);
  return swarm;
}

void SetPerRobotCounters(benchmark::State& state, double robots) {
  state.counters["per_robot"] =
      benchmark::Counter(robots, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["per_ray"] = benchmark::Counter(
      robots * kRaysPerRobot, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// One robot's read per iteration, cycling over `robots` (all if empty).
void SenseRobots(benchmark::State& state, bool early_out, const std::vector<int>* robots) {
  Swarm& swarm = GetSwarm(static_cast<int>(state.range(0)));
  const ProximityBackend& backend = early_out ? *swarm.backend : *swarm.cast_all;
  const size_t count = robots ? robots->size() : size_t(swarm.robots);
  if (count == 0) {
    state.SkipWithError("no such robots");
    return;
  }
  size_t k = 0;
  for (auto _ : state) {
    backend.SenseInstance(&swarm.scene, robots ? (*robots)[k] : static_cast<int>(k));
    if (++k == count) k = 0;
  }
  int detected = 0;
  for (const auto& r : proximity::Sensors(swarm.scene).rows) detected += r.detected;
  SetPerRobotCounters(state, double(state.iterations()));
  state.counters["detected_rays"] = detected;
  state.counters["robots"] = double(count);
}

void BM_SenseRobot(benchmark::State& state) { SenseRobots(state, true, nullptr); }
void BM_SenseRobot_CastAll(benchmark::State& state) { SenseRobots(state, false, nullptr); }
void BM_SenseNearWall(benchmark::State& state) {
  SenseRobots(state, true, &GetSwarm(static_cast<int>(state.range(0))).near_wall);
}
void BM_SenseNearWall_CastAll(benchmark::State& state) {
  SenseRobots(state, false, &GetSwarm(static_cast<int>(state.range(0))).near_wall);
}
void BM_SenseAlone(benchmark::State& state) {
  SenseRobots(state, true, &GetSwarm(static_cast<int>(state.range(0))).alone);
}
void BM_SenseAlone_CastAll(benchmark::State& state) {
  SenseRobots(state, false, &GetSwarm(static_cast<int>(state.range(0))).alone);
}

void BM_Update(benchmark::State& state) {
  Swarm& swarm = GetSwarm(static_cast<int>(state.range(0)));
  for (auto _ : state) swarm.backend->Update(swarm.scene);
  state.counters["per_robot"] =
      benchmark::Counter(double(state.iterations()) * swarm.robots,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_Build(benchmark::State& state) {
  Swarm& swarm = GetSwarm(static_cast<int>(state.range(0)));
  auto backend = proximity::MakeBackend();
  for (auto _ : state) backend->Build(swarm.scene, ProximitySettings{});
}

std::vector<GridItem> GridItems(int n) {
  std::mt19937_64 rng(3);
  const double side = std::sqrt(double(n));
  std::uniform_real_distribution<double> pos(-side / 2, side / 2);
  std::vector<GridItem> items(n);
  for (int i = 0; i < n; ++i) items[i] = {pos(rng), pos(rng), kBodyRadius, uint32_t(i)};
  return items;
}

void BM_GridBuild(benchmark::State& state) {
  const auto items = GridItems(static_cast<int>(state.range(0)));
  SpatialGrid grid;
  for (auto _ : state) grid.Build(items);
  state.counters["per_item"] =
      benchmark::Counter(double(state.iterations()) * items.size(),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_GridQuery(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto items = GridItems(n);
  SpatialGrid grid;
  grid.Build(items);
  // 64 Ki query centres whatever N, so that small N does not replay a short
  // sequence the branch predictor learns by heart.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pos(-std::sqrt(double(n)) / 2, std::sqrt(double(n)) / 2);
  std::vector<std::pair<double, double>> centres(1 << 16);
  for (auto& c : centres) c = {pos(rng), pos(rng)};
  std::vector<uint32_t> found;
  size_t i = 0, total = 0;
  for (auto _ : state) {
    grid.QueryCircle(centres[i].first, centres[i].second, 1.0, &found);
    total += found.size();
    i = (i + 1) & (centres.size() - 1);
  }
  state.counters["found"] = double(total) / double(state.iterations());
}

BENCHMARK(BM_SenseRobot)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_SenseRobot_CastAll)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_SenseNearWall)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_SenseNearWall_CastAll)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_SenseAlone)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_SenseAlone_CastAll)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_Update)->Arg(100)->Arg(1000)->Arg(10000);
BENCHMARK(BM_Build)->Arg(100)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_GridBuild)->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000);
BENCHMARK(BM_GridQuery)->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
