// The environment map (framework/environment.h) in the proximity module:
// its voxels are static boxes of no object for ray sensors and line of
// sight. The shared real map against the reference ray casts of
// /work/shared/maps/README.md, and small maps against exact distances.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/scene.h"
#include "modules/environment/octomap_map.h"
#include "modules/proximity/proximity.h"
#include "tests/shared_maps.h"

namespace swarmsim::proximity {
namespace {

constexpr double kTol = 1e-9;

// Orientation whose z axis points along `d` (a unit axis direction).
Quat LookAlong(const Vec3& d) {
  if (d.z > 0.5) return {};
  if (d.z < -0.5) return Quat::FromAxisAngle({1, 0, 0}, M_PI);
  return Quat::FromYaw(std::atan2(d.y, d.x)) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
}

ProximitySensorData Ray(double range) {
  ProximitySensorData d;
  d.settings.Edit().range = range;
  return d;
}

class EnvironmentProximityTest : public ::testing::Test {
 protected:
  ObjectId AddSensor(const Vec3& p, const Vec3& d, double range) {
    return proximity::AddSensor(&scene_, "s", {}, {p, LookAlong(d)}, Ray(range));
  }
  void Start(double resolution) {
    scene_.UpdateWorldPoses();
    ProximitySettings settings;
    settings.octree_resolution = resolution;
    backend_ = MakeBackend();
    backend_->Build(scene_, settings);
    backend_->Update(scene_);
    backend_->SenseSceneSensors(&scene_);
  }
  const ProximitySensorData& Reading(ObjectId sensor) { return proximity::Sensor(scene_, sensor); }

  Scene scene_;
  std::unique_ptr<ProximityBackend> backend_;
};

// The README's casts (OcTree::castRay from (0, 0, 1) and (0, 0, 20); `end` is
// the centre of the voxel hit) from 1 mm inside the same voxel column: the
// distance is to the near face of that voxel.
TEST_F(EnvironmentProximityTest, TheSharedMapAnswersTheReferenceRayCasts) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  scene_.set_environment(
      std::make_shared<const EnvironmentMap>(environment::ReadOctomap(path, "geb079.bt", {})));
  const Vec3 o{0.001, 0.001, 1};
  struct Cast {
    Vec3 origin, direction;
    double range, distance;  // distance < 0: nothing
  };
  const Cast casts[] = {
      {o, {0, 1, 0}, 30, 3.44 - 0.001},                 // end (0.04, 3.48, 1.00)
      {o, {0, -1, 0}, 30, 1.28 + 0.001},                // end (0.04, -1.32, 1.00)
      {o, {-1, 0, 0}, 30, 6.32 + 0.001},                // end (-6.36, 0.04, 1.00)
      {o, {1, 0, 0}, 30, -1},                           // down the corridor
      {o, {0, 0, -1}, 30, 1.0},                         // the floor, end (0.04, 0.04, -0.04)
      {o, {0, 0, 1}, 30, 1.72},                         // the ceiling, end (0.04, 0.04, 2.76)
      {{0.001, 0.001, 20}, {0, 0, -1}, 50, 20 - 2.80},  // the ceiling from above
  };
  std::vector<ObjectId> sensors;
  for (const Cast& c : casts) sensors.push_back(AddSensor(c.origin, c.direction, c.range));
  // Equal at the map's resolution and at others (voxels not on the octree's grid).
  for (double resolution : {0.08, 0.05, 0.13}) {
    Start(resolution);
    for (size_t i = 0; i < sensors.size(); ++i) {
      const ProximitySensorData& r = Reading(sensors[i]);
      if (casts[i].distance < 0) {
        EXPECT_FALSE(r.detected) << "cast " << i << " at resolution " << resolution;
        continue;
      }
      EXPECT_TRUE(r.detected) << "cast " << i << " at resolution " << resolution;
      EXPECT_NEAR(r.distance, casts[i].distance, kTol) << "cast " << i << " at " << resolution;
      // The map is no scene object: Lua reads sim.handle_world (-1).
      EXPECT_TRUE(r.detected_object.IsNull());
    }
  }
}

// A detection volume (a cone) sees the map's voxels too, as a null object.
TEST_F(EnvironmentProximityTest, AConeSeesTheSharedMap) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  scene_.set_environment(
      std::make_shared<const EnvironmentMap>(environment::ReadOctomap(path, "geb079.bt", {})));
  ProximitySensorData cone;
  cone.settings.Edit().volume = ProximityVolume::kCone;
  cone.settings.Edit().range = 5;
  cone.settings.Edit().angle = 10 * M_PI / 180;
  const ObjectId sensor =
      proximity::AddSensor(&scene_, "cone", {}, {{0.001, 0.001, 1}, LookAlong({0, 1, 0})}, cone);
  Start(0.08);
  const ProximitySensorData& r = Reading(sensor);
  EXPECT_TRUE(r.detected);
  EXPECT_GT(r.distance, 0.5);
  EXPECT_LE(r.distance, 3.44 - 0.001 + kTol);  // no farther than the wall on its axis
  EXPECT_TRUE(r.detected_object.IsNull());
}

TEST_F(EnvironmentProximityTest, LineOfSightIsBlockedByTheSharedMapsWalls) {
  SWARMSIM_NEED_SHARED_MAP(path, "geb079.bt");
  scene_.set_environment(
      std::make_shared<const EnvironmentMap>(environment::ReadOctomap(path, "geb079.bt", {})));
  Start(0.08);
  const Vec3 a{0.001, 0.001, 1};
  EXPECT_FALSE(backend_->SegmentBlocked(a, {0.001, 3.4, 1}));  // the wall is at y = 3.44
  EXPECT_TRUE(backend_->SegmentBlocked(a, {0.001, 3.6, 1}));
  EXPECT_TRUE(backend_->SegmentBlocked(a, {0.001, 3.6, 1}));
  EXPECT_FALSE(backend_->SegmentBlocked(a, {20, 0.001, 1}));  // down the corridor
  EXPECT_TRUE(backend_->SegmentBlocked(a, {-7, 0.001, 1}));   // the wall at x = -6.32
}

// A map of two voxel walls beside a static shape: distances are exact to
// the voxels' faces whatever the octree's resolution, a shape in front of
// the map hides it, and the map is never the robot's own.
TEST_F(EnvironmentProximityTest, MapVoxelsAreExactBoxesBesideShapes) {
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "test map";
  map->resolution = 0.1;
  // A wall at x in [1.013, 1.113] for y in [-0.5, 0.5], z in [0, 0.3], in voxels of 0.1.
  for (int j = -5; j < 5; ++j)
    for (int k = 0; k < 3; ++k)
      map->boxes.push_back({{1.013, j * 0.1, k * 0.1}, {1.113, (j + 1) * 0.1, (k + 1) * 0.1}});
  map->lo = {1.013, -0.5, 0};
  map->hi = {1.113, 0.5, 0.3};
  scene_.set_environment(map);
  ShapeData post;
  post.kind = ShapeKind::kBox;
  post.size = {0.1, 0.1, 0.3};
  const ObjectId shape = scene_.AddShape("post", {}, {{0.55, 0.3, 0.15}, {}}, post);
  const ObjectId free_ray = AddSensor({0.0, 0.0, 0.15}, {1, 0, 0}, 2);
  const ObjectId short_ray = AddSensor({0.0, 0.0, 0.15}, {1, 0, 0}, 1.0);
  const ObjectId post_ray = AddSensor({0.0, 0.3, 0.15}, {1, 0, 0}, 2);
  const ObjectId above = AddSensor({0.0, 0.0, 0.35}, {1, 0, 0}, 2);
  for (double resolution : {0.1, 0.05, 0.037}) {
    Start(resolution);
    EXPECT_TRUE(Reading(free_ray).detected) << resolution;
    EXPECT_NEAR(Reading(free_ray).distance, 1.013, kTol) << resolution;
    EXPECT_TRUE(Reading(free_ray).detected_object.IsNull());
    EXPECT_FALSE(Reading(short_ray).detected) << resolution;
    EXPECT_NEAR(Reading(post_ray).distance, 0.5, kTol) << resolution;
    EXPECT_EQ(Reading(post_ray).detected_object, shape);
    EXPECT_FALSE(Reading(above).detected) << resolution;
  }
}

}  // namespace
}  // namespace swarmsim::proximity
