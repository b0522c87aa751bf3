// Path planning (modules/planning) through the collision module's geometry.
//
// BM_PlanSe2: one RRT-Connect plan, holonomic SE2, of a 0.5 x 0.3 m box
// robot across a cluttered 20 x 20 m yard (walls, a long wall with two
// gaps, 40 crates and pillars), from the south-west corner to the
// north-east one; a new seed each iteration. Time per iteration = per plan
// (use --benchmark_repetitions and read the median).
//
// BM_PlanSwarm/threads: 100 robots spread over the yard each plan to the
// mirror point of their start at once, robots in parallel on `threads`
// workers (the planning module's ParallelFor, one robot per task): the
// time per batch at 1 and at 2 threads gives the speed-up.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "framework/scene.h"
#include "framework/scheduler.h"
#include "modules/collision/geometry.h"
#include "modules/planning/planner.h"

namespace swarmsim {
namespace {

using collision::Geometry;
using collision::Probe;
using collision::Target;
using planning::Plan;
using planning::PlanRequest;
using planning::PlanResult;
using planning::PlanStatus;
using planning::Space;

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

struct Yard {
  Scene scene;
  Geometry geometry;
  std::vector<uint32_t> robots;  // each robot's body slot
  std::vector<Pose> starts;
};

bool FreeSpot(const std::vector<Vec3>& crates, double x, double y) {
  for (const Vec3& c : crates)
    if (std::abs(x - c.x) < 0.9 && std::abs(y - c.y) < 0.9) return false;
  return std::abs(x) > 0.8 && std::abs(x) < 9.3 && std::abs(y) < 9.3;
}

std::unique_ptr<Yard> MakeYard(int robots) {
  auto yard = std::make_unique<Yard>();
  Scene& s = yard->scene;
  const Vec3 x_wall{20.4, 0.2, 0.5}, y_wall{0.2, 20.4, 0.5};
  s.AddShape("wall_n", {}, {{0, 10.1, 0.25}, {}}, Shape(ShapeKind::kBox, x_wall));
  s.AddShape("wall_s", {}, {{0, -10.1, 0.25}, {}}, Shape(ShapeKind::kBox, x_wall));
  s.AddShape("wall_e", {}, {{10.1, 0, 0.25}, {}}, Shape(ShapeKind::kBox, y_wall));
  s.AddShape("wall_w", {}, {{-10.1, 0, 0.25}, {}}, Shape(ShapeKind::kBox, y_wall));
  // A long wall along x = 0 with gaps at y = -5 and y = 5.
  s.AddShape("mid_s", {}, {{0, -8, 0.25}, {}}, Shape(ShapeKind::kBox, {0.3, 4, 0.5}));
  s.AddShape("mid_c", {}, {{0, 0, 0.25}, {}}, Shape(ShapeKind::kBox, {0.3, 8, 0.5}));
  s.AddShape("mid_n", {}, {{0, 8, 0.25}, {}}, Shape(ShapeKind::kBox, {0.3, 4, 0.5}));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-8.5, 8.5), yaw(-M_PI, M_PI);
  std::vector<Vec3> crates;
  while (crates.size() < 40) {
    const Vec3 c{u(rng), u(rng), 0.25};
    if (std::abs(c.x) < 1 || (std::abs(c.x) > 7.5 && std::abs(c.y) > 7.5)) continue;
    crates.push_back(c);
    if (crates.size() % 2)
      s.AddShape("crate", {}, {c, Quat::FromYaw(yaw(rng))},
                 Shape(ShapeKind::kBox, {0.8, 0.8, 0.5}));
    else
      s.AddShape("pillar", {}, {c, {}}, Shape(ShapeKind::kCylinder, {0.35, 0.35, 0.5}));
  }
  for (int i = 0; i < robots; ++i) {
    double x = -8.8, y = -8.8;
    if (robots > 1) do {
        x = u(rng);
        y = u(rng);
      } while (!FreeSpot(crates, x, y));
    const Pose X{{x, y, 0.1}, Quat::FromYaw(yaw(rng))};
    const ObjectId body = s.AddShape("body", {}, X, Shape(ShapeKind::kBox, {0.5, 0.3, 0.2}));
    s.MakeModelInstance(body, "car", "car#" + std::to_string(i));
    yard->robots.push_back(body.index());
    yard->starts.push_back(X);
  }
  s.UpdateWorldPoses();
  yard->geometry.Refresh(s);
  return yard;
}

PlanResult PlanFor(Yard& yard, size_t robot, const Pose& goal, uint64_t seed) {
  PlanRequest r;
  r.space = Space::kSe2;
  r.lo = {-10, -10, 0};
  r.hi = {10, 10, 2};
  r.resolution = 0.05;
  r.time_limit = 1;
  r.seed = seed;
  r.start = yard.starts[robot];
  r.goal = goal;
  const uint32_t slot = yard.robots[robot];
  Probe probe(yard.geometry, yard.scene, std::span<const uint32_t>(&slot, 1), r.start);
  const Target environment{EntitySpec::kEnvironment, {}};
  return Plan(r, [&](const Pose& X) { return !probe.Collides(X, environment); });
}

void BM_PlanSe2(benchmark::State& state) {
  auto yard = MakeYard(1);
  const Pose goal{{8.8, 8.8, 0.1}, Quat::FromYaw(M_PI / 2)};
  uint64_t seed = 1, solved = 0, plans = 0;
  double iterations = 0;
  for (auto _ : state) {
    const PlanResult p = PlanFor(*yard, 0, goal, seed++);
    solved += p.status == PlanStatus::kSolved;
    iterations += static_cast<double>(p.iterations);
    ++plans;
  }
  state.counters["solved"] = static_cast<double>(solved) / static_cast<double>(plans);
  state.counters["iterations"] = iterations / static_cast<double>(plans);
}
BENCHMARK(BM_PlanSe2)->Unit(benchmark::kMillisecond);

void BM_PlanSwarm(benchmark::State& state) {
  constexpr int kRobots = 100;
  auto yard = MakeYard(kRobots);
  TaskScheduler scheduler(static_cast<int>(state.range(0)));
  std::vector<PlanResult> results(kRobots);
  uint64_t round = 0;
  for (auto _ : state) {
    ++round;
    scheduler.ParallelFor(0, kRobots, 1, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        const Pose& X = yard->starts[i];
        const Pose goal{{-X.p.x, -X.p.y, X.p.z}, X.q};
        results[i] = PlanFor(*yard, static_cast<size_t>(i), goal, round * kRobots + i);
      }
    });
  }
  int solved = 0;
  for (const PlanResult& p : results) solved += p.status == PlanStatus::kSolved;
  state.counters["solved"] = solved;
}
BENCHMARK(BM_PlanSwarm)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
