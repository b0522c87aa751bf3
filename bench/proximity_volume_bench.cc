// One proximity sensor's reading: a ray (today's fast path) against a cone
// volume, over the same primitives (a box, a sphere, a cylinder and a
// capsule, static, within reach).
//
//   BM_Ray         the ray along +z: hits the box on its axis
//   BM_ConeInside  a 30 deg cone: every shape's own nearest point is inside
//                  it (the exact fast path of modules/proximity/volume.h)
//   BM_ConeCut     a 9 deg cone that cuts the box (its nearest point is
//                  outside): Dykstra's projections for the box
//   BM_PyramidCut  the same with a 9 deg pyramid
//   BM_PyramidEdge a 9 deg pyramid whose edge cuts the box (two sides active)
//
// Time is per reading (SenseSceneSensors with one sensor). The target:
// a cone reading at most 3x a ray's.
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>

#include "framework/scene.h"
#include "modules/proximity/proximity.h"

namespace swarmsim {
namespace {

ShapeData Shape(ShapeKind kind, const Vec3& size) {
  ShapeData s;
  s.kind = kind;
  s.size = size;
  return s;
}

struct OneSensor {
  Scene scene;
  std::unique_ptr<ProximityBackend> backend;
};

// A sensor at the origin looking along +z and four primitives ahead of it;
// `box_x` moves the box off the axis.
std::unique_ptr<OneSensor> Make(ProximityVolume volume, double angle_deg, double box_x,
                                double box_y = 0) {
  auto s = std::make_unique<OneSensor>();
  ProximitySensorData sensor;
  ProximitySensorSettings& settings = sensor.settings.Edit();
  settings.volume = volume;
  settings.range = 3;
  settings.angle = settings.angle_y = angle_deg * M_PI / 180;
  proximity::AddSensor(&s->scene, "s", {}, {}, sensor);
  s->scene.AddShape("box", {}, {{box_x, box_y, 1}, {}}, Shape(ShapeKind::kBox, {0.2, 0.2, 0.2}));
  s->scene.AddShape("sphere", {}, {{0.3, 0.3, 1.5}, {}}, Shape(ShapeKind::kSphere, {0.1, 0, 0}));
  s->scene.AddShape("cylinder", {}, {{-0.3, 0.2, 1.6}, {}},
                    Shape(ShapeKind::kCylinder, {0.1, 0, 0.3}));
  s->scene.AddShape("capsule", {}, {{0.2, -0.3, 1.7}, {}},
                    Shape(ShapeKind::kCapsule, {0.1, 0, 0.4}));
  s->scene.UpdateWorldPoses();
  s->backend = proximity::MakeBackend();
  s->backend->Build(s->scene, ProximitySettings{});
  s->backend->Update(s->scene);
  return s;
}

void Run(benchmark::State& state, OneSensor* s) {
  for (auto _ : state) {
    s->backend->SenseSceneSensors(&s->scene);
    benchmark::DoNotOptimize(proximity::Sensors(s->scene).rows[0].distance);
  }
  state.counters["distance"] = proximity::Sensors(s->scene).rows[0].distance;
  state.counters["detected"] = proximity::Sensors(s->scene).rows[0].detected;
}

void BM_Ray(benchmark::State& state) {
  auto s = Make(ProximityVolume::kRay, 0, 0);
  Run(state, s.get());
}
BENCHMARK(BM_Ray);

void BM_ConeInside(benchmark::State& state) {
  auto s = Make(ProximityVolume::kCone, 30, 0);
  Run(state, s.get());
}
BENCHMARK(BM_ConeInside);

void BM_ConeCut(benchmark::State& state) {
  auto s = Make(ProximityVolume::kCone, 9, 0.25);
  Run(state, s.get());
}
BENCHMARK(BM_ConeCut);

void BM_PyramidCut(benchmark::State& state) {
  auto s = Make(ProximityVolume::kPyramid, 9, 0.25);
  Run(state, s.get());
}
BENCHMARK(BM_PyramidCut);

void BM_PyramidEdge(benchmark::State& state) {
  auto s = Make(ProximityVolume::kPyramid, 9, 0.25, 0.25);
  Run(state, s.get());
}
BENCHMARK(BM_PyramidEdge);

}  // namespace
}  // namespace swarmsim

BENCHMARK_MAIN();
