// Minimum-distance cost (modules/collision) per robot and per mesh pair.
//
// BM_RobotDistances/N/coherent: N foot-bot-like robots (an upright
// cylinder body and two wheel cylinders on their sides) at 1 robot per
// m^2 among pillars and walls, each with two distance objects: to the
// static environment, and to everything else within 1 m. Each iteration
// moves every robot 5 mm (a slow swarm), refits (Geometry::Refresh) and
// measures both for every robot; coherent = 1 starts each from the last
// step's closest pair, 0 measures cold. items_per_second counts robots:
// its inverse is the cost per robot-tick.
//
// BM_MeshMesh/coherent: two 10,000-triangle spheres 0.3 m apart, one
// turning slowly about the other.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "framework/mesh.h"
#include "framework/scene.h"
#include "modules/collision/geometry.h"

namespace swarmsim {
namespace {

using collision::DistanceAnswer;
using collision::Geometry;
using collision::kNoSlot;
using collision::Target;

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

struct Swarm {
  Scene scene;
  std::vector<ObjectId> roots;
  std::vector<std::vector<uint32_t>> shapes;  // each robot's shapes (slots)
  Geometry geometry;
};

std::unique_ptr<Swarm> MakeSwarm(int n) {
  auto s = std::make_unique<Swarm>();
  const double side = std::sqrt(static_cast<double>(n));
  const double t = 0.1, c = side / 2 + t / 2;
  const Vec3 x_wall{side + 2 * t, t, 0.2}, y_wall{t, side + 2 * t, 0.2};
  s->scene.AddShape("wall_n", {}, {{0, c, 0.1}, {}}, Shape(ShapeKind::kBox, x_wall));
  s->scene.AddShape("wall_s", {}, {{0, -c, 0.1}, {}}, Shape(ShapeKind::kBox, x_wall));
  s->scene.AddShape("wall_e", {}, {{c, 0, 0.1}, {}}, Shape(ShapeKind::kBox, y_wall));
  s->scene.AddShape("wall_w", {}, {{-c, 0, 0.1}, {}}, Shape(ShapeKind::kBox, y_wall));
  // A pillar every 3 m.
  for (double x = -side / 2 + 1.5; x < side / 2; x += 3)
    for (double y = -side / 2 + 1.5; y < side / 2; y += 3)
      s->scene.AddShape("pillar", {}, {{x, y, 0.15}, {}},
                        Shape(ShapeKind::kCylinder, {0.15, 0.15, 0.3}));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), yaw(-M_PI, M_PI);
  const int per_row = static_cast<int>(std::ceil(side));
  const Quat wheel_turn = Quat::FromAxisAngle({1, 0, 0}, -M_PI / 2);
  for (int i = 0; i < n; ++i) {
    const double x = -side / 2 + (i % per_row + 0.5) * side / per_row + jitter(rng);
    const double y = -side / 2 + (i / per_row + 0.5) * side / per_row + jitter(rng);
    const Pose X{{x, y, 0.073}, Quat::FromAxisAngle({0, 0, 1}, yaw(rng))};
    const ObjectId body =
        s->scene.AddShape("body", {}, X, Shape(ShapeKind::kCylinder, {0.085, 0.085, 0.146}));
    s->scene.AddShape("leftWheel", body, {{0, 0.07, -0.044}, wheel_turn},
                      Shape(ShapeKind::kCylinder, {0.029, 0.029, 0.02}));
    s->scene.AddShape("rightWheel", body, {{0, -0.07, -0.044}, wheel_turn},
                      Shape(ShapeKind::kCylinder, {0.029, 0.029, 0.02}));
    s->scene.MakeModelInstance(body, "bot", "bot#" + std::to_string(i));
    s->roots.push_back(body);
  }
  s->scene.UpdateWorldPoses();
  s->geometry.Refresh(s->scene);
  for (const ObjectId root : s->roots) {
    std::vector<uint32_t> sub;
    s->scene.CollectSubtree(root.index(), &sub);
    std::sort(sub.begin(), sub.end());
    s->shapes.push_back(s->geometry.ShapesOf(s->scene, sub));
  }
  return s;
}

void BM_RobotDistances(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const bool coherent = state.range(1) != 0;
  const std::unique_ptr<Swarm> s = MakeSwarm(n);
  struct Hint {
    uint32_t a = kNoSlot, b = kNoSlot;
  };
  std::vector<Hint> env(n), near(n);
  int64_t step = 0;
  double sum = 0;
  for (auto _ : state) {
    state.PauseTiming();
    // 5 mm forward, turning a little.
    for (int i = 0; i < n; ++i) {
      const Pose X = s->scene.world_pose(s->roots[i]);
      const double turn = 0.01 * ((i + step) % 3 - 1);
      s->scene.SetWorldPose(s->roots[i], {X.p + X.q.Rotate({0.005, 0, 0}),
                                          X.q * Quat::FromAxisAngle({0, 0, 1}, turn)});
    }
    s->scene.UpdateWorldPoses();
    ++step;
    state.ResumeTiming();
    s->geometry.Refresh(s->scene);
    for (int i = 0; i < n; ++i) {
      const DistanceAnswer e =
          s->geometry.Distance(s->shapes[i], Target{EntitySpec::kEnvironment, {}}, INFINITY,
                               coherent ? env[i].a : kNoSlot, coherent ? env[i].b : kNoSlot);
      const DistanceAnswer o =
          s->geometry.Distance(s->shapes[i], Target{EntitySpec::kEverythingElse, {}}, 1.0,
                               coherent ? near[i].a : kNoSlot, coherent ? near[i].b : kNoSlot);
      env[i] = {e.s1, e.s2};
      near[i] = {o.s1, o.s2};
      sum += e.distance + (o.found ? o.distance : 0);
    }
  }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_RobotDistances)
    ->ArgsProduct({{1000}, {1, 0}})
    ->ArgNames({"robots", "coherent"})
    ->Unit(benchmark::kMillisecond);

// A UV sphere of radius r with about 2 * stacks * slices triangles.
std::shared_ptr<const TriangleMesh> Sphere(double r, int stacks, int slices) {
  std::vector<Vec3> v;
  std::vector<MeshTriangle> t;
  v.push_back({0, 0, r});
  for (int i = 1; i < stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j < slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      v.push_back(
          {r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th)});
    }
  }
  v.push_back({0, 0, -r});
  const auto at = [&](int i, int j) {
    return static_cast<uint32_t>(1 + (i - 1) * slices + j % slices);
  };
  for (int j = 0; j < slices; ++j) t.push_back({{0, at(1, j), at(1, j + 1)}});
  for (int i = 1; i + 1 < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      t.push_back({{at(i, j), at(i + 1, j), at(i + 1, j + 1)}});
      t.push_back({{at(i, j), at(i + 1, j + 1), at(i, j + 1)}});
    }
  const uint32_t south = static_cast<uint32_t>(v.size() - 1);
  for (int j = 0; j < slices; ++j) t.push_back({{south, at(stacks - 1, j + 1), at(stacks - 1, j)}});
  return std::make_shared<const TriangleMesh>("sphere", std::move(v), std::move(t));
}

void BM_MeshMesh(benchmark::State& state) {
  const bool coherent = state.range(0) != 0;
  Scene scene;
  ShapeData mesh = Shape(ShapeKind::kMesh, {1, 1, 1});
  mesh.mesh = Sphere(0.5, 50, 100);  // 9,900 triangles
  const ObjectId a = scene.AddShape("a", {}, {{0, 0, 0}, {}}, mesh);
  const ObjectId b = scene.AddShape("b", {}, {{1.3, 0, 0}, {}}, mesh);
  scene.MakeModelInstance(b, "b", "b#0");  // moving
  scene.UpdateWorldPoses();
  Geometry geometry;
  geometry.Refresh(scene);
  const std::vector<uint32_t> sa{a.index()}, sb{b.index()};
  uint32_t hint_a = kNoSlot, hint_b = kNoSlot;
  double angle = 0, sum = 0;
  for (auto _ : state) {
    state.PauseTiming();
    angle += 0.002;
    scene.SetWorldPose(b, {{1.3 * std::cos(angle), 1.3 * std::sin(angle), 0},
                           Quat::FromAxisAngle({0, 0, 1}, angle)});
    scene.UpdateWorldPoses();
    geometry.Refresh(scene);
    state.ResumeTiming();
    const DistanceAnswer d =
        geometry.Distance(sa, Target{EntitySpec::kPath, sb}, INFINITY, coherent ? hint_a : kNoSlot,
                          coherent ? hint_b : kNoSlot);
    hint_a = d.s1;
    hint_b = d.s2;
    sum += d.distance;
  }
  benchmark::DoNotOptimize(sum);
}
BENCHMARK(BM_MeshMesh)->Arg(1)->Arg(0)->ArgName("coherent")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
