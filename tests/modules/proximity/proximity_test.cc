#include "modules/proximity/proximity.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "modules/proximity/ray_cast.h"
#include "modules/proximity/static_index.h"

namespace swarmsim::proximity {
namespace {

constexpr double kTol = 1e-9;

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

// Orientation whose z axis points along heading `yaw` in the xy plane.
Quat LookAlong(double yaw) { return Quat::FromYaw(yaw) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2); }
Pose Looking(const Vec3& p, double yaw) { return {p, LookAlong(yaw)}; }

ProximitySensorData Ray(double range) {
  ProximitySensorData d;
  d.settings.Edit().range = range;
  return d;
}

struct Robot {
  ObjectId root, body;
  std::vector<ObjectId> sensors;
  int instance = -1;
};

// A robot: a dummy root at X_WR, an upright cylinder body (radius, height
// 0.12, base on the floor) and sensors at the given poses in the root frame.
Robot AddRobot(Scene* scene, const Pose& X_WR, double body_radius,
               const std::vector<Pose>& sensor_poses, double range) {
  Robot robot;
  const int k = static_cast<int>(scene->instances().size());
  robot.root = scene->AddDummy("bot", {}, X_WR);
  robot.body = scene->AddShape("body", robot.root, {{0, 0, 0.06}, {}}, Cylinder(body_radius, 0.12));
  for (const Pose& X_RS : sensor_poses)
    robot.sensors.push_back(proximity::AddSensor(scene, "sensor", robot.root, X_RS, Ray(range)));
  robot.instance = scene->MakeModelInstance(robot.root, "bot", "bot#" + std::to_string(k));
  return robot;
}

// A scene, the backend, and the calls World::Sense makes.
class ProximityTest : public ::testing::Test {
 protected:
  void Start(double resolution = 0.05) {
    scene_.UpdateWorldPoses();
    ProximitySettings settings;
    settings.octree_resolution = resolution;
    backend_ = MakeBackend();
    backend_->Build(scene_, settings);
  }
  void Sense() {
    scene_.UpdateWorldPoses();
    backend_->Update(scene_);
    for (size_t i = 0; i < scene_.instances().size(); ++i)
      backend_->SenseInstance(&scene_, static_cast<int>(i));
    backend_->SenseSceneSensors(&scene_);
  }
  const ProximitySensorData& Reading(ObjectId sensor) { return proximity::Sensor(scene_, sensor); }
  void ExpectHit(ObjectId sensor, double distance, ObjectId object) {
    const ProximitySensorData& r = Reading(sensor);
    EXPECT_TRUE(r.detected);
    EXPECT_NEAR(r.distance, distance, kTol);
    EXPECT_NEAR(r.p_SD().x, 0, kTol);
    EXPECT_NEAR(r.p_SD().y, 0, kTol);
    EXPECT_NEAR(r.p_SD().z, distance, kTol);
    EXPECT_EQ(r.detected_object, object);
  }
  void ExpectNothing(ObjectId sensor) {
    const ProximitySensorData& r = Reading(sensor);
    EXPECT_FALSE(r.detected);
    EXPECT_EQ(r.distance, 0);
    EXPECT_EQ(r.p_SD(), Vec3{});
    EXPECT_TRUE(r.detected_object.IsNull());
  }

  Scene scene_;
  std::unique_ptr<ProximityBackend> backend_;
};

// --- The static environment (octree) -------------------------------------------------

TEST_F(ProximityTest, WallFaceAlongX) {
  // A box wall whose near face is at x = 0.95 (its centre at x = 1).
  const ObjectId wall = scene_.AddShape("wall", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({0, 0, 0}, 0), Ray(2));
  Start();
  Sense();
  ExpectHit(sensor, 0.95, wall);
}

TEST_F(ProximityTest, DistancesAreNotQuantisedToVoxels) {
  // Neither the face (x = 0.9321) nor the sensor (x = 0.0123) lies on the
  // 0.05 m voxel grid; the reading must be exact, and equal at any resolution.
  scene_.AddShape("wall", {}, {{0.9321 + 0.25, 0.01, 0.013}, {}}, Box(0.5, 2, 1));
  const ObjectId sensor =
      proximity::AddSensor(&scene_, "s", {}, Looking({0.0123, 0.0071, 0.0312}, 0), Ray(2));
  for (double resolution : {0.05, 0.2, 0.013}) {
    Start(resolution);
    Sense();
    EXPECT_NEAR(Reading(sensor).distance, 0.9321 - 0.0123, kTol) << resolution;
  }
}

TEST_F(ProximityTest, BoxRotated30DegreesAboutZ) {
  // Box centred at (1, 0), half extents (0.1, 0.3), turned 30 degrees. In the
  // box frame the ray meets the face x' = -0.1 where (t - 1) cos 30 = -0.1,
  // at y' = 0.1 tan 30 (well inside |y'| <= 0.3): t = 1 - 0.1 / cos 30.
  const ObjectId box =
      scene_.AddShape("box", {}, {{1, 0, 0}, Quat::FromYaw(M_PI / 6)}, Box(0.2, 0.6, 0.5));
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({0, 0, 0}, 0), Ray(2));
  Start();
  Sense();
  ExpectHit(sensor, 1 - 0.1 / std::cos(M_PI / 6), box);
}

TEST_F(ProximityTest, VerticalCylinder) {
  const ObjectId post = scene_.AddShape("post", {}, {{1.3, 0, 0.2}, {}}, Cylinder(0.2, 1));
  const ObjectId offset = scene_.AddShape("post2", {}, {{1.3, 2.1, 0.2}, {}}, Cylinder(0.2, 1));
  const ObjectId centred = proximity::AddSensor(&scene_, "s", {}, Looking({0, 0, 0}, 0), Ray(2));
  // 0.1 m beside the second post's axis: t = d - sqrt(r^2 - 0.1^2).
  const ObjectId beside = proximity::AddSensor(&scene_, "s2", {}, Looking({0, 2.0, 0}, 0), Ray(2));
  Start();
  Sense();
  ExpectHit(centred, 1.3 - 0.2, post);
  ExpectHit(beside, 1.3 - std::sqrt(0.2 * 0.2 - 0.1 * 0.1), offset);
}

TEST_F(ProximityTest, CylinderCapFromBelow) {
  // A sensor looking straight up at a horizontal disc (cylinder lying flat).
  const ObjectId disc = scene_.AddShape("disc", {}, {{0.02, 0, 0.5}, {}}, Cylinder(0.3, 0.1));
  const ObjectId up = proximity::AddSensor(&scene_, "up", {}, {{0, 0, 0}, {}}, Ray(1));
  Start();
  Sense();
  ExpectHit(up, 0.45, disc);
}

TEST_F(ProximityTest, Sphere) {
  const ObjectId ball = scene_.AddShape("ball", {}, {{0.7, 0, 0.1}, {}}, Sphere(0.15));
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({0, 0, 0}, 0), Ray(1));
  Start();
  Sense();
  ExpectHit(sensor, 0.7 - std::sqrt(0.15 * 0.15 - 0.1 * 0.1), ball);
}

TEST_F(ProximityTest, RayJustBesideAShapeSeesNothing) {
  // The box's lower face is 1e-7 m above the ray; the twin box is 1e-7 m into it.
  scene_.AddShape("miss", {}, {{1, 0.1 + 1e-7, 0}, {}}, Box(0.2, 0.2, 0.2));
  const ObjectId hit = scene_.AddShape("hit", {}, {{1, 5 + 0.1 - 1e-7, 0}, {}}, Box(0.2, 0.2, 0.2));
  const ObjectId past = proximity::AddSensor(&scene_, "a", {}, Looking({0, 0, 0}, 0), Ray(2));
  const ObjectId grazing = proximity::AddSensor(&scene_, "b", {}, Looking({0, 5, 0}, 0), Ray(2));
  Start();
  Sense();
  ExpectNothing(past);
  ExpectHit(grazing, 0.9, hit);
}

TEST_F(ProximityTest, OutOfRangeSeesNothing) {
  const ObjectId wall = scene_.AddShape("wall", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  const ObjectId short_ray =
      proximity::AddSensor(&scene_, "a", {}, Looking({0, 0, 0}, 0), Ray(0.9));
  const ObjectId exact = proximity::AddSensor(&scene_, "b", {}, Looking({0, 0.5, 0}, 0), Ray(0.95));
  const ObjectId away = proximity::AddSensor(&scene_, "c", {}, Looking({0, -0.5, 0}, M_PI), Ray(5));
  Start();
  Sense();
  ExpectNothing(short_ray);
  ExpectHit(exact, 0.95, wall);  // the range is inclusive
  ExpectNothing(away);
}

TEST_F(ProximityTest, NearestOfTwoObstacles) {
  scene_.AddShape("far", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  const ObjectId near = scene_.AddShape("near", {}, {{0.5, 0, 0}, {}}, Sphere(0.05));
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({0, 0, 0}, 0), Ray(2));
  Start();
  Sense();
  ExpectHit(sensor, 0.45, near);
}

TEST_F(ProximityTest, RayStartingInsideAWallReadsZero) {
  const ObjectId wall = scene_.AddShape("wall", {}, {{0, 0, 0}, {}}, Box(0.4, 0.4, 0.4));
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({0.1, 0, 0}, 0), Ray(1));
  Start();
  Sense();
  ExpectHit(sensor, 0, wall);
}

TEST_F(ProximityTest, SceneSensorIgnoresTheShapeItIsMountedOn) {
  const ObjectId wall = scene_.AddShape("wall", {}, {{0, 0, 0}, {}}, Box(0.2, 2, 1));
  scene_.AddShape("other", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  // Mounted on the wall's face, looking away from it, and into it.
  const ObjectId out = proximity::AddSensor(&scene_, "out", wall, Looking({0.1, 0, 0}, 0), Ray(2));
  const ObjectId in = proximity::AddSensor(&scene_, "in", wall, Looking({0.1, 0, 0}, M_PI), Ray(2));
  Start();
  Sense();
  EXPECT_NEAR(Reading(out).distance, 0.95 - 0.1, kTol);
  ExpectNothing(in);
}

TEST_F(ProximityTest, BadSettingsAreUserErrors) {
  scene_.AddShape("wall", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  EXPECT_THROW(Start(0), Error);
  EXPECT_THROW(Start(-1), Error);
  // Shapes beyond the octree's keys are no error (static_index_test.cc).
  scene_.AddShape("far away", {}, {{5000, 0, 0}, {}}, Box(0.1, 2, 1));
  EXPECT_NO_THROW(Start(0.05));
  EXPECT_NO_THROW(Start(0.5));
}

// --- Robots (spatial grid) --------------------------------------------------------

TEST_F(ProximityTest, OwnBodyIsNotDetected) {
  // Sensors on the body surface, and one at the body's centre (inside it).
  const Robot robot = AddRobot(
      &scene_, {}, 0.085, {Looking({0.085, 0, 0.06}, 0), Looking({0, 0, 0.06}, M_PI / 2)}, 0.1);
  Start();
  Sense();
  ExpectNothing(robot.sensors[0]);
  ExpectNothing(robot.sensors[1]);
}

TEST_F(ProximityTest, OtherRobotDetectedAtExactDistance) {
  const Robot a = AddRobot(&scene_, {}, 0.085, {Looking({0.085, 0, 0.06}, 0)}, 0.2);
  const Robot b = AddRobot(&scene_, {{0.3, 0, 0}, Quat::FromYaw(M_PI)}, 0.085,
                           {Looking({0.085, 0, 0.06}, 0)}, 0.2);
  Start();
  Sense();
  ExpectHit(a.sensors[0], 0.3 - 2 * 0.085, b.body);
  ExpectHit(b.sensors[0], 0.3 - 2 * 0.085, a.body);
  // B drives 0.05 m away: the next step's reading follows.
  scene_.SetLocalPose(b.root, {{0.35, 0, 0}, Quat::FromYaw(M_PI)});
  Sense();
  ExpectHit(a.sensors[0], 0.35 - 2 * 0.085, b.body);
  // And out of range.
  scene_.SetLocalPose(b.root, {{0.5, 0, 0}, Quat::FromYaw(M_PI)});
  Sense();
  ExpectNothing(a.sensors[0]);
}

TEST_F(ProximityTest, NearestOfRobotAndWall) {
  scene_.AddShape("wall", {}, {{1.0, 0, 0}, {}}, Box(0.1, 2, 1));
  const Robot a = AddRobot(&scene_, {}, 0.085, {Looking({0.085, 0, 0.06}, 0)}, 2);
  const Robot b = AddRobot(&scene_, {{0.6, 0, 0}, {}}, 0.085, {}, 0.2);
  Start();
  Sense();
  ExpectHit(a.sensors[0], 0.6 - 0.085 - 0.085, b.body);
  scene_.SetLocalPose(b.root, {{0.6, 3, 0}, {}});
  Sense();
  ExpectHit(a.sensors[0], 0.95 - 0.085, scene_.FindObject("/wall"));
}

TEST_F(ProximityTest, SceneSensorSeesRobotsAndDynamicShapes) {
  const Robot bot = AddRobot(&scene_, {{1, 0, 0}, {}}, 0.1, {}, 0.1);
  ShapeData crate = Box(0.2, 0.2, 0.2);
  crate.dynamic = true;
  const ObjectId box = scene_.AddShape("crate", {}, {{0, 1, 0.1}, {}}, crate);
  const ObjectId east = proximity::AddSensor(&scene_, "east", {}, Looking({0, 0, 0.05}, 0), Ray(2));
  const ObjectId north =
      proximity::AddSensor(&scene_, "north", {}, Looking({0, 0, 0.05}, M_PI / 2), Ray(2));
  Start();
  Sense();
  ExpectHit(east, 0.9, bot.body);
  ExpectHit(north, 0.9, box);
  // The dynamic crate moves (it is not frozen into the octree).
  scene_.SetLocalPose(box, {{0, 1.5, 0.1}, {}});
  Sense();
  ExpectHit(north, 1.4, box);
}

TEST_F(ProximityTest, TiltedRobotShapeStillFoundByTheGrid) {
  // A long box lying along the ray direction, tilted: its world footprint
  // reaches far beyond ShapeData::BoundingRadius about its origin.
  const ObjectId root = scene_.AddDummy("bot", {}, {{1.0, 0, 0}, {}});
  const ObjectId plank = scene_.AddShape(
      "plank", root, {{0, 0, 0}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, Box(0.1, 0.1, 1.6));
  scene_.MakeModelInstance(root, "bot", "bot#0");
  const ObjectId sensor = proximity::AddSensor(&scene_, "s", {}, Looking({-0.5, 0, 0}, 0), Ray(1));
  Start();
  Sense();
  ExpectHit(sensor, 0.7, plank);
}

// --- Cross-checks ---------------------------------------------------------------------

// Random static shapes (arbitrary 3D orientations) and random rays: the
// octree path must agree exactly with testing every shape.
TEST_F(ProximityTest, MatchesBruteForceOnRandomScenes) {
  std::mt19937_64 rng(1234);
  std::uniform_real_distribution<double> pos(-2, 2), size(0.02, 0.6), angle(-M_PI, M_PI);
  std::vector<PlacedShape> all;
  for (int i = 0; i < 60; ++i) {
    ShapeData shape = i % 3 == 0   ? Box(size(rng), size(rng), size(rng))
                      : i % 3 == 1 ? Cylinder(size(rng) / 2, size(rng))
                                   : Sphere(size(rng) / 2);
    const Pose X_WS{{pos(rng), pos(rng), pos(rng) / 4},
                    Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))};
    all.push_back(PlaceShape(shape, X_WS, scene_.AddShape("o", {}, X_WS, shape), -1));
  }
  std::vector<ObjectId> sensors;
  std::vector<Pose> poses;
  for (int i = 0; i < 3000; ++i) {
    poses.push_back({{pos(rng), pos(rng), pos(rng) / 4},
                     Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))});
    sensors.push_back(proximity::AddSensor(&scene_, "s", {}, poses.back(), Ray(1.5)));
  }
  for (double resolution : {0.05, 0.17}) {
    Start(resolution);
    Sense();
    int detections = 0;
    for (size_t i = 0; i < sensors.size(); ++i) {
      const Vec3 p = poses[i].p, d = poses[i].q.Rotate({0, 0, 1});
      double best = INFINITY, t;
      ObjectId id;
      for (const PlacedShape& s : all)
        if (RayCast(s, p, d, 1.5, &t) && t < best) best = t, id = s.id;
      const ProximitySensorData& r = Reading(sensors[i]);
      ASSERT_EQ(r.detected, std::isfinite(best)) << "sensor " << i << " at res " << resolution;
      if (!r.detected) continue;
      ++detections;
      EXPECT_NEAR(r.distance, best, 1e-12);
      EXPECT_EQ(r.detected_object, id);
    }
    EXPECT_GT(detections, 300);
  }
}

// A crowded arena: readings match brute force, and SenseInstance from
// several threads at once gives the serial readings.
TEST_F(ProximityTest, SwarmMatchesBruteForceAndConcurrentSensingMatchesSerial) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> pos(0.2, 9.8), yaw(-M_PI, M_PI);
  std::vector<Pose> ring;
  for (int k = 0; k < 24; ++k) {
    const double a = 2 * M_PI * k / 24;
    ring.push_back(Looking({0.085 * std::cos(a), 0.085 * std::sin(a), 0.06}, a));
  }
  for (int i = 0; i < 300; ++i)
    AddRobot(&scene_, {{pos(rng), pos(rng), 0}, Quat::FromYaw(yaw(rng))}, 0.085, ring, 0.3);
  for (int side = 0; side < 4; ++side) {
    const double a = side * M_PI / 2;
    scene_.AddShape("wall", {},
                    {{5 + 5.05 * std::cos(a), 5 + 5.05 * std::sin(a), 0.1}, Quat::FromYaw(a)},
                    Box(0.1, 10.2, 0.2));
  }
  Start();
  Sense();
  std::vector<ProximitySensorData> serial(proximity::Sensors(scene_).rows.begin(),
                                          proximity::Sensors(scene_).rows.end());
  // Serial readings agree with testing every shape but the robot's own.
  std::vector<PlacedShape> all;
  for (size_t r = 0; r < scene_.shapes().size(); ++r) {
    const uint32_t slot = scene_.shape_owners()[r];
    all.push_back(PlaceShape(scene_.shapes()[r], scene_.world_pose_at(slot), scene_.IdAt(slot),
                             scene_.instance_of_at(slot)));
  }
  int detected = 0;
  for (size_t row = 0; row < serial.size(); ++row) {
    const uint32_t slot = proximity::Sensors(scene_).owners[row];
    const Pose& X_WS = scene_.world_pose_at(slot);
    const Vec3 d = X_WS.q.Rotate({0, 0, 1});
    double best = INFINITY, t;
    ObjectId id;
    for (const PlacedShape& s : all)
      if (s.instance != scene_.instance_of_at(slot) && RayCast(s, X_WS.p, d, 0.3, &t) && t < best)
        best = t, id = s.id;
    ASSERT_EQ(serial[row].detected, std::isfinite(best)) << row;
    if (!serial[row].detected) continue;
    ++detected;
    EXPECT_NEAR(serial[row].distance, best, 1e-12);
    EXPECT_EQ(serial[row].detected_object, id);
  }
  EXPECT_GT(detected, 50);
  for (auto& r : proximity::MutableSensors(&scene_).rows) r = Ray(r.range());  // clear the readings
  std::vector<std::thread> threads;
  const int n = static_cast<int>(scene_.instances().size());
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = t; i < n; i += 4) backend_->SenseInstance(&scene_, i);
    });
  for (auto& t : threads) t.join();
  for (size_t row = 0; row < serial.size(); ++row) {
    const ProximitySensorData& r = proximity::Sensors(scene_).rows[row];
    ASSERT_EQ(r.detected, serial[row].detected) << row;
    ASSERT_EQ(r.distance, serial[row].distance) << row;
    ASSERT_EQ(r.detected_object, serial[row].detected_object) << row;
  }
}

// Update places the moving shapes on every thread, in blocks of shape rows:
// a swarm spanning several blocks, with static shapes (not placed) and free
// dynamic ones (placed) among the robots' rows, reads the same bits as with
// the shapes placed on one thread, and what testing every shape reads.
TEST_F(ProximityTest, ShapesPlacedOnSeveralThreadsAreSeenAsWhenPlacedOnOne) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(0.2, 29.8), yaw(-M_PI, M_PI);
  std::vector<Pose> ring;
  for (int k = 0; k < 4; ++k)
    ring.push_back(Looking({0.085 * std::cos(k * M_PI / 2), 0.085 * std::sin(k * M_PI / 2), 0.06},
                           k * M_PI / 2));
  for (int i = 0; i < 10000; ++i) {
    AddRobot(&scene_, {{pos(rng), pos(rng), 0}, Quat::FromYaw(yaw(rng))}, 0.085, ring, 0.3);
    if (i % 5 == 0)
      scene_.AddShape("post", {}, {{pos(rng), pos(rng), 0.1}, {}}, Cylinder(0.05, 0.2));
    if (i % 7 == 0) {
      ShapeData crate = Box(0.2, 0.2, 0.2);
      crate.dynamic = true;
      scene_.AddShape("crate", {}, {{pos(rng), pos(rng), 0.1}, {}}, crate);
    }
  }
  ASSERT_GT(scene_.shapes().size(), 3 * 4096u);  // several blocks
  scene_.UpdateWorldPoses();
  auto& rows = proximity::MutableSensors(&scene_).rows;
  const auto sense = [&](TaskScheduler* scheduler) {
    for (ProximitySensorData& r : rows) {  // scribbled first
      r.detected = true;
      r.distance = -7;
      r.detected_object = ObjectId{12345, 6};
    }
    ProximitySettings settings;
    settings.scheduler = scheduler;
    std::unique_ptr<ProximityBackend> backend = MakeBackend();
    backend->Build(scene_, settings);
    backend->Update(scene_);
    for (size_t i = 0; i < scene_.instances().size(); ++i)
      backend->SenseInstance(&scene_, static_cast<int>(i));
    return std::vector<ProximitySensorData>(rows.begin(), rows.end());
  };
  const std::vector<ProximitySensorData> one = sense(nullptr);
  TaskScheduler two_threads(2);
  const std::vector<ProximitySensorData> two = sense(&two_threads);
  int detected = 0;
  for (size_t row = 0; row < rows.size(); ++row) {
    ASSERT_EQ(two[row].detected, one[row].detected) << row;
    ASSERT_EQ(std::bit_cast<uint64_t>(two[row].distance),
              std::bit_cast<uint64_t>(one[row].distance))
        << row;
    ASSERT_EQ(two[row].detected_object, one[row].detected_object) << row;
    detected += one[row].detected;
  }
  EXPECT_GT(detected, 1000);
  // Every 97th sensor against every shape but its robot's own: the nearest,
  // and on a tie (a ray starting inside two shapes reads 0 for both) a
  // static shape before a moving one, then the lower shape row.
  std::vector<PlacedShape> all;
  for (size_t r = 0; r < scene_.shapes().size(); ++r) {
    const uint32_t slot = scene_.shape_owners()[r];
    all.push_back(PlaceShape(scene_.shapes()[r], scene_.world_pose_at(slot), scene_.IdAt(slot),
                             scene_.instance_of_at(slot)));
  }
  for (size_t row = 0; row < rows.size(); row += 97) {
    const uint32_t slot = proximity::Sensors(scene_).owners[row];
    const Pose& X_WS = scene_.world_pose_at(slot);
    const Vec3 d = X_WS.q.Rotate({0, 0, 1});
    double best = INFINITY, t;
    bool best_static = false;
    ObjectId id;
    for (size_t r = 0; r < all.size(); ++r) {
      const PlacedShape& shape = all[r];
      if (shape.instance == scene_.instance_of_at(slot) || !RayCast(shape, X_WS.p, d, 0.3, &t))
        continue;
      const bool is_static = shape.instance < 0 && !scene_.shapes()[r].dynamic;
      if (t < best || (t == best && is_static && !best_static))
        best = t, best_static = is_static, id = shape.id;
    }
    ASSERT_EQ(two[row].detected, std::isfinite(best)) << row;
    if (!two[row].detected) continue;
    EXPECT_NEAR(two[row].distance, best, 1e-12) << row;
    EXPECT_EQ(two[row].detected_object, id) << row;
  }
}

// --- The early-out: skipped rays read exactly what cast rays read -------------------

// Same bits: a reading the early-out forgot to write, or wrote as "nothing"
// where a cast would have found something, shows up here.
bool SameBits(const ProximitySensorData& a, const ProximitySensorData& b) {
  return a.detected == b.detected &&
         std::bit_cast<uint64_t>(a.distance) == std::bit_cast<uint64_t>(b.distance) &&
         a.detected_object == b.detected_object;
}

// A scene read twice per step: by the backend with the early-out and by one
// that casts every ray. Each pass starts from scribbled readings.
struct TwinBackends {
  void Start(double resolution = 0.05) {
    scene.UpdateWorldPoses();
    ProximitySettings settings;
    settings.octree_resolution = resolution;
    early_out = MakeBackend();
    early_out->Build(scene, settings);
    cast_all = MakeBackend({.early_out = false});
    cast_all->Build(scene, settings);
  }
  void Pass(ProximityBackend* backend) {
    for (ProximitySensorData& r : proximity::MutableSensors(&scene).rows) {
      r.detected = true;
      r.distance = -7;
      r.detected_object = ObjectId{12345, 6};
    }
    backend->Update(scene);
    for (size_t i = 0; i < scene.instances().size(); ++i)
      if (scene.instances()[i].alive) backend->SenseInstance(&scene, static_cast<int>(i));
    backend->SenseSceneSensors(&scene);
  }
  // Reads with both backends; expects the same bits; returns the detections.
  int SenseBoth() {
    scene.UpdateWorldPoses();
    Pass(cast_all.get());
    const std::vector<ProximitySensorData> expected(proximity::Sensors(scene).rows.begin(),
                                                    proximity::Sensors(scene).rows.end());
    Pass(early_out.get());
    int detected = 0, mismatches = 0;
    for (size_t row = 0; row < expected.size(); ++row) {
      const ProximitySensorData& got = proximity::Sensors(scene).rows[row];
      detected += expected[row].detected;
      if (SameBits(got, expected[row]) || ++mismatches > 5) continue;
      ADD_FAILURE() << "sensor row " << row << " ("
                    << scene.PathOf(scene.IdAt(proximity::Sensors(scene).owners[row]))
                    << "): early-out detected " << got.detected << " at " << got.distance
                    << ", casting every ray detected " << expected[row].detected << " at "
                    << expected[row].distance;
    }
    EXPECT_EQ(mismatches, 0);
    return detected;
  }
  const ProximitySensorData& Reading(ObjectId sensor) { return proximity::Sensor(scene, sensor); }

  Scene scene;
  std::unique_ptr<ProximityBackend> early_out, cast_all;
};

// Random 3D scenes: static shapes in any orientation (and sometimes a
// floor), robots at random heights and tilts with a ring of sensors plus
// off-centre, tilted, zero- and negative-range sensors, dynamic crates and
// scene sensors (one mounted on a crate). Robots move between steps.
TEST(EarlyOutTest, MatchesCastingEveryRayOnRandomScenes) {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> unit(0, 1), angle(-M_PI, M_PI);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  int total_detected = 0, total_sensors = 0;
  for (int scene_index = 0; scene_index < 12; ++scene_index) {
    SCOPED_TRACE(scene_index);
    TwinBackends twin;
    Scene& scene = twin.scene;
    const bool floor = scene_index % 3 == 0;
    const bool tilted = scene_index % 2 == 1;
    if (floor) scene.AddShape("floor", {}, {{0, 0, -0.05}, {}}, Box(6, 6, 0.1));
    for (int i = 0; i < 25; ++i) {
      const ShapeData shape = i % 3 == 0
                                  ? Box(uniform(0.02, 0.5), uniform(0.02, 0.5), uniform(0.05, 0.4))
                              : i % 3 == 1 ? Cylinder(uniform(0.02, 0.2), uniform(0.05, 0.4))
                                           : Sphere(uniform(0.02, 0.2));
      const Quat q = tilted ? Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))
                            : Quat::FromYaw(angle(rng));
      scene.AddShape("obstacle", {}, {{uniform(-2, 2), uniform(-2, 2), uniform(0, 0.3)}, q}, shape);
    }
    std::vector<Robot> robots;
    for (int i = 0; i < 60; ++i) {
      std::vector<Pose> sensors;
      for (int k = 0; k < 8; ++k) {
        const double a = 2 * M_PI * k / 8;
        sensors.push_back(Looking({0.085 * std::cos(a), 0.085 * std::sin(a), 0.06}, a));
      }
      // Off-centre and tilted: looking down at the floor, up, anywhere.
      sensors.push_back({{0.05, -0.03, 0.1}, Quat::FromRollPitchYaw(0, M_PI * 0.8, angle(rng))});
      sensors.push_back({{-0.04, 0.02, 0.12}, Quat::FromYaw(angle(rng))});
      sensors.push_back({{uniform(-0.1, 0.1), uniform(-0.1, 0.1), uniform(0, 0.2)},
                         Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))});
      const double height = floor ? uniform(0, 0.3) : 0;
      const Quat q =
          tilted ? Quat::FromRollPitchYaw(uniform(-0.5, 0.5), uniform(-0.5, 0.5), angle(rng))
                 : Quat::FromYaw(angle(rng));
      robots.push_back(AddRobot(&scene, {{uniform(-2.2, 2.2), uniform(-2.2, 2.2), height}, q},
                                0.085, sensors, uniform(0.02, 0.3)));
      // A tilted wheel: its footprint is not its bounding radius.
      scene.AddShape("wheel", robots.back().body,
                     {{0, 0.07, -0.03}, Quat::FromAxisAngle({1, 0, 0}, M_PI / 2)},
                     Cylinder(0.03, 0.02));
      if (i % 10 == 0)
        proximity::MutableSensor(&scene, robots.back().sensors[9]).settings.Edit().range = 0;
      if (i % 10 == 1)
        proximity::MutableSensor(&scene, robots.back().sensors[9]).settings.Edit().range = -1;
    }
    ShapeData crate = Box(0.15, 0.15, 0.15);
    crate.dynamic = true;
    std::vector<ObjectId> crates;
    for (int i = 0; i < 4; ++i)
      crates.push_back(scene.AddShape(
          "crate", {}, {{uniform(-2, 2), uniform(-2, 2), 0.075}, Quat::FromYaw(angle(rng))},
          crate));
    proximity::AddSensor(&scene, "on_crate", crates[0], Looking({0.075, 0, 0}, 0), Ray(0.5));
    proximity::AddSensor(&scene, "into_crate", crates[0], Looking({0.075, 0, 0}, M_PI), Ray(0.5));
    for (int i = 0; i < 6; ++i)
      proximity::AddSensor(&scene, "free", {},
                           {{uniform(-2, 2), uniform(-2, 2), uniform(0, 0.3)},
                            Quat::FromRollPitchYaw(angle(rng), angle(rng), angle(rng))},
                           Ray(uniform(0.05, 0.5)));
    twin.Start(scene_index % 4 == 3 ? 0.13 : 0.05);
    for (int step = 0; step < 3; ++step) {
      total_detected += twin.SenseBoth();
      total_sensors += static_cast<int>(proximity::Sensors(scene).rows.size());
      // Each robot moves a little; some bump into their neighbours.
      for (const Robot& robot : robots) {
        Pose X = scene.world_pose(robot.root);
        X.p = X.p + Vec3{uniform(-0.05, 0.05), uniform(-0.05, 0.05), 0};
        X.q = Quat::FromYaw(uniform(-0.3, 0.3)) * X.q;
        scene.SetLocalPose(robot.root, X);
      }
      scene.SetLocalPose(crates[1], {{uniform(-2, 2), uniform(-2, 2), 0.075}, {}});
    }
    if (::testing::Test::HasFailure()) break;
  }
  // Enough of both kinds for the comparison to mean something.
  EXPECT_GT(total_detected, total_sensors / 20);
  EXPECT_LT(total_detected, total_sensors / 2);
}

void ExpectReading(const ProximitySensorData& r, bool detected, double distance, ObjectId object) {
  EXPECT_EQ(r.detected, detected);
  EXPECT_NEAR(r.distance, detected ? distance : 0, kTol);
  EXPECT_EQ(r.detected_object, detected ? object : ObjectId{});
}

// Obstacles at the very edge of reach, just inside and just outside: a wall,
// another robot's body, and a floor under a tilted sensor of a raised robot.
TEST(EarlyOutTest, MatchesCastingEveryRayAtTheEdgeOfReach) {
  const double range = 0.1, rim = 0.085;
  for (double gap : {-1e-6, -1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6}) {
    SCOPED_TRACE(gap);
    const bool inside = gap <= -1e-9, outside = gap >= 1e-9;  // else: either, but the same
    {
      // A wall whose face is `gap` beyond the end of the ray.
      TwinBackends twin;
      const ObjectId wall = twin.scene.AddShape(
          "wall", {}, {{rim + range + gap + 0.05, 0, 0.1}, {}}, Box(0.1, 2, 0.2));
      const Robot a = AddRobot(&twin.scene, {}, rim, {Looking({rim, 0, 0.06}, 0)}, range);
      twin.Start();
      twin.SenseBoth();
      if (inside || outside) ExpectReading(twin.Reading(a.sensors[0]), inside, range + gap, wall);
    }
    {
      // Another robot whose body is `gap` beyond the end of the ray.
      TwinBackends twin;
      const Robot a = AddRobot(&twin.scene, {}, rim, {Looking({rim, 0, 0.06}, 0)}, range);
      const Robot b = AddRobot(&twin.scene, {{2 * rim + range + gap, 0, 0}, {}}, rim, {}, range);
      twin.Start();
      twin.SenseBoth();
      if (inside || outside) ExpectReading(twin.Reading(a.sensors[0]), inside, range + gap, b.body);
    }
    {
      // A robot raised 0.3 m: a sensor 45 degrees down sees the floor (top at
      // z = 0) `gap` beyond its reach; its level sensor sees nothing.
      TwinBackends twin;
      const ObjectId floor = twin.scene.AddShape("floor", {}, {{0, 0, -0.05}, {}}, Box(4, 4, 0.1));
      const double distance = 0.3 * std::sqrt(2.0);
      const Robot a = AddRobot(
          &twin.scene, {{0.3, -0.2, 0.3}, {}}, rim,
          {{{0, 0, 0}, Quat::FromAxisAngle({0, 1, 0}, M_PI * 0.75)}, Looking({rim, 0, 0}, 0)},
          distance - gap);
      twin.Start();
      twin.SenseBoth();
      if (inside || outside) ExpectReading(twin.Reading(a.sensors[0]), inside, distance, floor);
      ExpectReading(twin.Reading(a.sensors[1]), false, 0, {});
    }
  }
}

// Robots and sensors added, copied and removed after the start are read
// (the backend keeps its sensor lists in step with the scene).
TEST(EarlyOutTest, RobotsAddedOrRemovedAfterTheStartAreRead) {
  TwinBackends twin;
  Scene& scene = twin.scene;
  const ObjectId wall = scene.AddShape("wall", {}, {{1.0, 0, 0.1}, {}}, Box(0.1, 2, 0.2));
  const Robot a = AddRobot(&scene, {{0.8, 0, 0}, {}}, 0.085, {Looking({0.085, 0, 0.06}, 0)}, 0.1);
  twin.Start();
  twin.SenseBoth();
  ExpectReading(twin.Reading(a.sensors[0]), true, 0.95 - 0.885, wall);
  // Added after the start, and read without an Update (as a plugin might).
  const Robot b = AddRobot(&scene, {{0.8, 0.5, 0}, {}}, 0.085, {Looking({0.085, 0, 0.06}, 0)}, 0.1);
  scene.UpdateWorldPoses();
  twin.early_out->SenseInstance(&scene, b.instance);
  ExpectReading(twin.Reading(b.sensors[0]), true, 0.95 - 0.885, wall);
  twin.SenseBoth();
  ExpectReading(twin.Reading(b.sensors[0]), true, 0.95 - 0.885, wall);
  // A sensor added to a robot that has been read.
  const ObjectId extra =
      proximity::AddSensor(&scene, "extra", a.root, Looking({0.085, 0.02, 0.06}, 0), Ray(0.1));
  twin.SenseBoth();
  ExpectReading(twin.Reading(extra), true, 0.95 - 0.885, wall);
  // A copy of b, then a removed: the copy reads, b still reads.
  const ObjectId copy = scene.DuplicateSubtree(b.root, {});
  scene.SetLocalPose(copy, {{0.81, -0.5, 0}, {}});
  scene.RemoveSubtree(a.root);
  twin.SenseBoth();
  ExpectReading(twin.Reading(b.sensors[0]), true, 0.95 - 0.885, wall);
  ExpectReading(twin.Reading(scene.FindObject("./sensor", copy)), true, 0.95 - 0.895, wall);
}

}  // namespace
}  // namespace swarmsim::proximity
