// modules/proximity/static_index.cc: the octree of the static environment.
//
// Static shapes far from the origin (issue 26): the proximity module's
// octree spans 65,536 voxels per axis (3,276.8 m at 0.05 m), but world
// coordinates go to 1e6 m. A static environment away from the origin moves
// the octree; one wider than it keeps the shapes beyond apart, tested one
// by one. Either way the readings are the exact ones, as brute force finds
// them, and nothing is an error. And its coarse map (the early-out's first
// test) is conservative.
#include "modules/proximity/static_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "framework/environment.h"
#include "framework/scene.h"
#include "modules/proximity/proximity.h"
#include "modules/proximity/ray_cast.h"

namespace swarmsim::proximity {
namespace {

ShapeData RandomShape(std::mt19937_64* rng, int i) {
  std::uniform_real_distribution<double> size(0.05, 0.8);
  ShapeData s;
  s.kind = i % 3 == 0 ? ShapeKind::kBox : i % 3 == 1 ? ShapeKind::kCylinder : ShapeKind::kSphere;
  s.size = s.kind == ShapeKind::kBox ? Vec3{size(*rng), size(*rng), size(*rng)}
                                     : Vec3{size(*rng) / 2, 0, size(*rng)};
  return s;
}

// Static shapes in clusters around `centres`, and ray sensors among them;
// every reading (both backends: early-out and casting every ray) against
// brute force over all shapes.
void ExpectExactReadings(const std::vector<Vec3>& centres, double resolution) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> offset(-2, 2), angle(-M_PI, M_PI);
  Scene scene;
  std::vector<PlacedShape> all;
  for (const Vec3& c : centres)
    for (int i = 0; i < 25; ++i) {
      const ShapeData shape = RandomShape(&rng, i);
      const Pose X_WS{c + Vec3{offset(rng), offset(rng), offset(rng) / 4},
                      Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))};
      all.push_back(PlaceShape(shape, X_WS, scene.AddShape("o", {}, X_WS, shape), -1));
    }
  std::vector<ObjectId> sensors;
  for (const Vec3& c : centres)
    for (int i = 0; i < 400; ++i) {
      ProximitySensorData ray;
      ray.settings.Edit().range = 1.5;
      sensors.push_back(
          proximity::AddSensor(&scene, "s", {},
                               {c + Vec3{offset(rng), offset(rng), offset(rng) / 4},
                                Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))},
                               ray));
    }
  scene.UpdateWorldPoses();
  ProximitySettings settings;
  settings.octree_resolution = resolution;
  for (bool early_out : {true, false}) {
    SCOPED_TRACE(early_out ? "early out" : "casting every ray");
    std::unique_ptr<ProximityBackend> backend = MakeBackend({.early_out = early_out});
    ASSERT_NO_THROW(backend->Build(scene, settings));
    backend->Update(scene);
    backend->SenseSceneSensors(&scene);
    int detections = 0;
    for (size_t i = 0; i < sensors.size(); ++i) {
      const Pose X_WS = scene.world_pose(sensors[i]);
      const Vec3 d = X_WS.q.Rotate({0, 0, 1});
      double best = INFINITY, t;
      ObjectId id;
      for (const PlacedShape& s : all)
        if (RayCast(s, X_WS.p, d, 1.5, &t) && t < best) best = t, id = s.id;
      const ProximitySensorData& r = proximity::Sensor(scene, sensors[i]);
      ASSERT_EQ(r.detected, std::isfinite(best)) << "sensor " << i;
      if (!r.detected) continue;
      ++detections;
      EXPECT_NEAR(r.distance, best, 1e-9) << "sensor " << i;
      EXPECT_EQ(r.detected_object, id) << "sensor " << i;
    }
    EXPECT_GT(detections, 100 * static_cast<int>(centres.size()));
  }
}

TEST(ProximityFarTest, EnvironmentAwayFromTheOriginReadsExactly) {
  // 5 km out: beyond the 1,638 m an octree centred on the origin reaches.
  ExpectExactReadings({{5000, -3000, 2}}, 0.05);
  ExpectExactReadings({{-900000, 4000, -50}}, 0.05);
}

TEST(ProximityFarTest, EnvironmentWiderThanTheOctreeReadsExactly) {
  // 6 km from one cluster to the other: no placement of 65,536 voxels
  // holds both.
  ExpectExactReadings({{-3000, 0, 0}, {3000, 0, 0}}, 0.05);
  ExpectExactReadings({{0, 0, 0}, {0, 999000, 0}, {0, -999000, 10}}, 0.05);
  // Both clusters beyond an octree of 1 mm voxels centred on the origin
  // (+-32.8 m): every shape tested one by one.
  ExpectExactReadings({{-40, 0, 0}, {40, 0, 0}}, 1e-3);
}

// The index's box queries see the shapes beyond the octree too.
TEST(ProximityFarTest, BoxQueriesIncludeShapesBeyondTheOctree) {
  Scene scene;
  ShapeData box;
  box.size = {1, 1, 1};
  scene.AddShape("near", {}, {{0, 0, 0}, {}}, box);
  scene.AddShape("far_a", {}, {{4000, 0, 0}, {}}, box);
  scene.AddShape("far_b", {}, {{-4000, 0, 0}, {}}, box);
  scene.UpdateWorldPoses();
  StaticIndex index;
  ASSERT_NO_THROW(index.Build(scene, 0.05));
  for (double x : {0.0, 4000.0, -4000.0}) {
    SCOPED_TRACE(x);
    const Vec3 lo{x - 0.6, -0.1, -0.1}, hi{x - 0.4, 0.1, 0.1};
    EXPECT_TRUE(index.AnyOccupied(lo, hi));
    EXPECT_TRUE(index.MayBeOccupied(lo, hi));
    std::vector<uint32_t> found;
    index.ShapesInBox(lo, hi, &found);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_NEAR(index.shapes()[found[0]].X_WS.p.x, x, 1e-9);
    const Vec3 empty_lo{x + 2, 2, 2}, empty_hi{x + 3, 3, 3};
    EXPECT_FALSE(index.AnyOccupied(empty_lo, empty_hi));
    EXPECT_FALSE(index.MayBeOccupied(empty_lo, empty_hi));
    double t;
    uint32_t s;
    ASSERT_TRUE(index.CastRay({x - 2, 0, 0}, {1, 0, 0}, 5, {}, &t, &s));
    EXPECT_NEAR(t, 1.5, 1e-9);
  }
}

TEST(ProximityFarTest, EnvironmentMapFarFromTheOriginIsIndexed) {
  Scene scene;
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "far.bt";
  map->resolution = 0.1;
  map->boxes = {{{-0.1, -0.1, 0}, {0.1, 0.1, 0.2}}, {{3000, -0.1, 0}, {3000.2, 0.1, 0.2}}};
  map->lo = {-0.1, -0.1, 0};
  map->hi = {3000.2, 0.1, 0.2};
  scene.set_environment(map);
  scene.UpdateWorldPoses();
  StaticIndex index;
  ASSERT_NO_THROW(index.Build(scene, 0.01));  // 300,000 voxels apart
  double t;
  uint32_t s;
  ASSERT_TRUE(index.CastRay({2999, 0, 0.1}, {1, 0, 0}, 5, {}, &t, &s));
  EXPECT_NEAR(t, 1, 1e-9);
  ASSERT_TRUE(index.CastRay({1, 0, 0.1}, {-1, 0, 0}, 5, {}, &t, &s));
  EXPECT_NEAR(t, 0.9, 1e-9);
}

// --- The coarse map ------------------------------------------------------------------

ShapeData Box(double x, double y, double z) {
  ShapeData s;
  s.kind = ShapeKind::kBox;
  s.size = {x, y, z};
  return s;
}
ShapeData Cylinder(double radius, double height) {
  ShapeData s;
  s.kind = ShapeKind::kCylinder;
  s.size = {radius, 0, height};
  return s;
}
ShapeData Sphere(double radius) {
  ShapeData s;
  s.kind = ShapeKind::kSphere;
  s.size = {radius, 0, 0};
  return s;
}

// The coarse map never says "nothing" where the octree has an occupied voxel.
TEST(StaticIndexTest, CoarseMapIsConservative) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> pos(-3, 3), size(0.01, 0.8), angle(-M_PI, M_PI),
      extent(0, 0.5);
  Scene scene;
  for (int i = 0; i < 40; ++i) {
    const ShapeData shape = i % 3 == 0   ? Box(size(rng), size(rng), size(rng))
                            : i % 3 == 1 ? Cylinder(size(rng) / 2, size(rng))
                                         : Sphere(size(rng) / 2);
    scene.AddShape("o", {},
                   {{pos(rng), pos(rng), pos(rng) / 2},
                    Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))},
                   shape);
  }
  scene.UpdateWorldPoses();
  for (double resolution : {0.05, 0.011, 0.3}) {
    StaticIndex index;
    index.Build(scene, resolution);
    int occupied = 0, ruled_out = 0;
    for (int i = 0; i < 20000; ++i) {
      const Vec3 lo{pos(rng) * 1.2, pos(rng) * 1.2, pos(rng) / 2};
      const Vec3 hi = lo + Vec3{extent(rng), extent(rng), extent(rng)} * (i % 2 ? 0.2 : 1);
      const bool any = index.AnyOccupied(lo, hi);
      const bool may = index.MayBeOccupied(lo, hi);
      ASSERT_TRUE(may || !any) << "box " << i << " at resolution " << resolution;
      occupied += any;
      ruled_out += !may;
    }
    EXPECT_GT(occupied, 1000) << resolution;
    EXPECT_GT(ruled_out, 1000) << resolution;
  }
}

}  // namespace
}  // namespace swarmsim::proximity
