// The blob cameras' module (modules/blobs/module.cc): which LEDs a camera
// sees — range, field of view, occlusion by static shapes, other robots and
// the map, its own robot's LEDs and switched-off LEDs left out — with the
// colour, distance, bearing and elevation of each, in bearing order; noise;
// copies of a model; the same readings at 1 and 2 threads.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "tests/modules/blobs/blob_world.h"

namespace swarmsim {
namespace {

using namespace blobs_test;  // blob_world.h

TEST(BlobCameraTest, SeesTheLedsWithinRangeOnly) {
  BlobWorld w;
  BlobCameraRow row;
  row.range = 1.0;
  const ObjectId camera = w.CameraRobot(0, 0, 0, row);
  const ObjectId near = w.LedRobot(0.6, 0, kRed);
  w.LedRobot(-1.2, 0, kGreen);  // 1.2 m away
  w.LedRobot(0, 0.99, kBlue);   // 0.99 m in the plane, but 0.044 m lower: still within 1 m
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_EQ(blobs[0].color, kRed);
  EXPECT_NEAR(blobs[0].distance, std::hypot(0.6, 0.044), 1e-12);
  EXPECT_EQ(blobs[0].led, w.scene().children(near)[0]);
  EXPECT_EQ(blobs[1].color, kBlue);
}

TEST(BlobCameraTest, BearingAndElevationAreTheLedsDirectionInTheCamerasFrame) {
  BlobWorld w;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  const ObjectId root = w.Robot(0.5, 0.5, 0, /*body=*/false);
  w.Led(root, {0, 0, 0.127}, kRed);  // level with the camera, at 45 degrees
  std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_NEAR(blobs[0].bearing, M_PI / 4, 1e-12);
  EXPECT_NEAR(blobs[0].elevation, 0, 1e-12);
  EXPECT_NEAR(blobs[0].distance, std::sqrt(0.5), 1e-12);

  // Turned by 90 degrees, the camera sees it at -45 degrees; 0.3 m above
  // it at 0.4 m in the plane, at atan(0.3 / 0.4) up.
  BlobWorld turned;
  const ObjectId c2 = turned.CameraRobot(0, 0, M_PI / 2);
  turned.Led(turned.Robot(0.4, 0, 0, false), {0, 0, 0.127 + 0.3}, kGreen);
  turned.Led(turned.Robot(0.5, 0.5, 0, false), {0, 0, 0.127}, kRed);
  blobs = turned.See(c2);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_NEAR(blobs[0].bearing, -M_PI / 2, 1e-12);
  EXPECT_NEAR(blobs[0].elevation, std::atan2(0.3, 0.4), 1e-12);
  EXPECT_EQ(blobs[0].color, kGreen);
  EXPECT_NEAR(blobs[1].bearing, -M_PI / 4, 1e-12);
  EXPECT_EQ(blobs[1].color, kRed);
}

TEST(BlobCameraTest, ReadsInBearingOrderWithEachLedsColour) {
  BlobWorld w;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  // Counter-clockwise from behind (-180): blue at -90, red at 0, green at 90, blue at 180.
  w.LedRobot(0, -0.5, kBlue);
  w.LedRobot(0.5, 0, kRed);
  w.LedRobot(0, 0.5, kGreen);
  w.LedRobot(-0.7, -0.0, kBlue);  // straight behind, from below: still +pi
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 4u);
  const Vec3 colors[4] = {kBlue, kRed, kGreen, kBlue};
  const double bearings[4] = {-M_PI / 2, 0, M_PI / 2, M_PI};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(blobs[i].color, colors[i]) << i;
    EXPECT_NEAR(blobs[i].bearing, bearings[i], 1e-12) << i;
  }
}

TEST(BlobCameraTest, AFieldOfViewKeepsWhatIsWithinHalfOfItOfTheCamerasX) {
  BlobWorld w;
  BlobCameraRow row;
  row.fov = M_PI / 2;           // +-45 degrees
  row.vertical_fov = M_PI / 3;  // +-30 degrees
  const ObjectId camera = w.CameraRobot(0, 0, 0, row);
  const auto at = [&](double bearing_deg, double elevation_deg, const Vec3& color) {
    const double b = bearing_deg * M_PI / 180, e = elevation_deg * M_PI / 180;
    const ObjectId root = w.Robot(0.5 * std::cos(b), 0.5 * std::sin(b), 0, false);
    w.Led(root, {0, 0, 0.127 + 0.5 * std::tan(e)}, color);  // 0.5 m in the plane
  };
  at(30, 0, kRed);      // seen
  at(60, 0, kGreen);    // beside the view
  at(180, 0, kBlue);    // behind
  at(-40, 20, kBlue);   // seen
  at(-20, 40, kGreen);  // above the view
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_NEAR(blobs[0].bearing, -40 * M_PI / 180, 1e-12);
  EXPECT_NEAR(blobs[0].elevation, 20 * M_PI / 180, 1e-12);
  EXPECT_EQ(blobs[1].color, kRed);
}

TEST(BlobCameraTest, ItsOwnRobotsLedsAndSwitchedOffOrBlackLedsAreNotSeen) {
  BlobWorld w;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  w.Led(w.scene().parent(camera), {0.05, 0, 0.083}, kRed);  // its own robot's
  const ObjectId other = w.Robot(0.5, 0);
  w.Led(other, {0, 0, 0.083}, kGreen, /*on=*/false);
  w.Led(other, {0, 0.02, 0.083}, {0, 0, 0});  // black
  const ObjectId lit = w.Led(other, {0, -0.02, 0.083}, kBlue);
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(blobs[0].led, lit);
}

TEST(BlobCameraTest, AStaticBoxHidesTheLedsBehindItUnlessOcclusionIsOff) {
  BlobWorld w;
  BlobCameraRow no_occlusion;
  no_occlusion.occlusion = false;
  no_occlusion.range = 1.5;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  const ObjectId sees_all = w.CameraRobot(0, -0.3, 0, no_occlusion);
  // A wall 0.5 m high across +x at x = 0.5, 0.4 m wide: hides the LED at
  // x = 0.9 behind it, not the one at 45 degrees beside it, nor the one
  // high above it (the camera, 0.2 m up, looks over the wall).
  w.scene().AddShape("wall", {}, {{0.5, 0, 0.25}, {}}, Box({0.05, 0.4, 0.5}));
  w.LedRobot(0.9, 0, kRed);
  w.LedRobot(0.6, 0.6, kGreen);
  w.Led(w.Robot(0.6, 0.05, 0, false), {0, 0, 0.827}, kBlue);  // 0.9 m up
  std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_EQ(blobs[0].color, kBlue);
  EXPECT_EQ(blobs[1].color, kGreen);
  EXPECT_EQ(w.Blobs(sees_all).size(), 3u);
}

TEST(BlobCameraTest, AnotherRobotsBodyHidesAnLedButTheLedsOwnBodyDoesNot) {
  BlobWorld w;
  // Camera and LEDs at mid-body height (inside their own bodies, as a ring
  // of LEDs would be): the robot at x = 0.5 stands between the camera and
  // the LED at x = 1; its own LED at its centre is seen.
  const ObjectId camera_robot = w.Robot(0, 0);
  const ObjectId camera = w.Camera(camera_robot, {});
  const ObjectId between = w.Robot(0.5, 0);
  const ObjectId middle = w.Led(between, {}, kGreen);
  w.Led(w.Robot(1.0, 0), {}, kRed);
  const ObjectId beside = w.Led(w.Robot(0.7, 0.5), {}, kBlue);
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_EQ(blobs[0].led, middle);
  EXPECT_EQ(blobs[1].led, beside);
}

TEST(BlobCameraTest, TheMapsVoxelsHideLedsToo) {
  BlobWorld w;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  w.LedRobot(0.8, 0, kRed);
  w.LedRobot(0, 0.8, kGreen);
  // A map block across +x between the camera and the red LED.
  auto map = std::make_shared<EnvironmentMap>();
  map->source = "test";
  map->resolution = 0.05;
  map->boxes.push_back({{0.4, -0.2, 0}, {0.45, 0.2, 0.4}});
  map->lo = map->boxes[0].lo;
  map->hi = map->boxes[0].hi;
  w.scene().set_environment(map);
  const std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(blobs[0].color, kGreen);
}

// Cameras and LEDs of no robot: a scene LED inside the static post it hangs
// from is seen, one inside another static box is not; a scene camera sees
// every robot's LED.
TEST(BlobCameraTest, TheShapesASceneLedHangsFromDoNotHideIt) {
  BlobWorld w;
  const ObjectId camera = w.CameraRobot(0, 0, 0);
  const ObjectId post = w.scene().AddShape("post", {}, {{0.6, 0, 0.25}, {}}, Cylinder(0.05, 0.5));
  const ObjectId mounted = w.Led(post, {0, 0, -0.05}, kRed);  // 0.2 m up, inside the post
  const ObjectId crate = w.scene().AddShape("crate", {}, {{0, 0.6, 0.1}, {}}, Box({0.2, 0.2, 0.2}));
  w.Led({}, {0, 0.6, 0.15}, kGreen);  // inside the crate, which it does not hang from
  (void)crate;
  BlobCameraRow wide;
  wide.range = 1.5;
  const ObjectId scene_camera = w.Camera({}, {{-0.5, 0, 0.3}, {}}, wide);
  const ObjectId robot_led = w.Led(w.scene().parent(camera), {0, 0, 0.083}, kBlue);
  std::vector<Blob> blobs = w.See(camera);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(blobs[0].led, mounted);
  blobs = w.Blobs(scene_camera);
  ASSERT_EQ(blobs.size(), 2u);  // the robot's LED and the post's; the crate's is hidden
  EXPECT_EQ(blobs[0].led, robot_led);
  EXPECT_EQ(blobs[1].led, mounted);
}

// Noise: over many steps the bearings and distances of an LED spread
// about the true ones by the settings' standard deviations; the readings
// are the same in a second world (the stream is keyed by seed, camera and
// step, not by anything that runs).
std::vector<Blob> NoisyReadings(int steps) {
  BlobWorld w;
  BlobCameraRow row;
  row.angle_noise = 0.05;
  row.distance_noise = 0.1;
  const ObjectId camera = w.CameraRobot(0, 0, 0, row);
  w.Led(w.Robot(0.5, 0, 0, false), {0, 0, 0.127}, kRed);  // bearing 0, elevation 0, 0.5 m
  std::vector<Blob> out;
  for (int i = 0; i < steps; ++i) {
    const std::vector<Blob> blobs = w.See(camera);
    EXPECT_EQ(blobs.size(), 1u);
    if (!blobs.empty()) out.push_back(blobs[0]);
  }
  return out;
}

TEST(BlobCameraTest, NoiseSpreadsReadingsByTheGivenDeviationsTheSameEveryRun) {
  const std::vector<Blob> a = NoisyReadings(400), b = NoisyReadings(400);
  ASSERT_EQ(a.size(), 400u);
  double bearing2 = 0, elevation2 = 0, distance_mean = 0, distance2 = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].bearing, b[i].bearing);
    EXPECT_EQ(a[i].distance, b[i].distance);
    bearing2 += a[i].bearing * a[i].bearing;
    elevation2 += a[i].elevation * a[i].elevation;
    distance_mean += a[i].distance / a.size();
    distance2 += (a[i].distance - 0.5) * (a[i].distance - 0.5);
  }
  const double n = static_cast<double>(a.size());
  EXPECT_NEAR(std::sqrt(bearing2 / n), 0.05, 0.01);
  EXPECT_NEAR(std::sqrt(elevation2 / n), 0.05, 0.01);
  EXPECT_NEAR(std::sqrt(distance2 / n), 0.05, 0.01);  // 10% of 0.5 m
  EXPECT_NEAR(distance_mean, 0.5, 0.01);
  EXPECT_NE(a[0].bearing, a[1].bearing);  // a new draw each step
}

// failure_probability: the camera sees nothing in that share of the steps
// (within 4 binomial standard deviations), and exactly what is there in the
// others.
TEST(BlobCameraTest, AFailingCameraSeesNothingAtTheConfiguredRate) {
  BlobWorld w;
  BlobCameraRow row;
  row.failure = 0.3;
  const ObjectId camera = w.CameraRobot(0, 0, 0, row);
  w.Led(w.Robot(0.5, 0, 0, false), {0, 0, 0.127}, kRed);
  int blind = 0;
  for (int i = 0; i < 2000; ++i) {
    const std::vector<Blob> blobs = w.See(camera);
    if (blobs.empty()) {
      ++blind;
    } else {
      ASSERT_EQ(blobs.size(), 1u);
      EXPECT_NEAR(blobs[0].distance, 0.5, 1e-9);
    }
  }
  EXPECT_NEAR(blind, 600, 4 * std::sqrt(2000 * 0.3 * 0.7));
}

TEST(BlobCameraTest, CopiesOfAModelWithAnLedAndACameraSeeEachOther) {
  BlobWorld w;
  const ObjectId first = w.Robot(0, 0);
  w.Led(first, {0, 0, 0.083}, kRed);
  w.Camera(first, {{0, 0, 0.127}, {}});
  // Three copies on a line 0.4 m apart (range 1 m): the ends see two LEDs,
  // the middle ones three, never their own.
  for (int i = 1; i < 4; ++i) {
    const ObjectId copy = w.scene().DuplicateSubtree(first, {});
    w.scene().SetWorldPose(copy, {{0.4 * i, 0, 0.073}, {}});
  }
  ASSERT_EQ(w.scene().instances().size(), 4u);
  w.world().Step();
  ObjectType camera_type;
  ASSERT_TRUE(w.scene().FindType(kBlobCameraTypeName, &camera_type));
  for (int i = 0; i < 4; ++i) {
    const ObjectId root = w.scene().instance(i).root;
    const ObjectId camera = w.scene().FindObject("./camera", root);
    const ObjectId led = w.scene().FindObject("./led", root);
    ASSERT_FALSE(camera.IsNull());
    const std::vector<Blob>& blobs = w.Blobs(camera);
    EXPECT_EQ(blobs.size(), i == 0 || i == 3 ? 2u : 3u) << i;
    for (const Blob& b : blobs) EXPECT_NE(b.led, led) << i;
  }
}

// A swarm of robots at random spots (LEDs of three colours, some cameras
// with a narrow view, some pillars); every reading.
std::vector<std::vector<Blob>> SwarmReadings(int threads) {
  BlobWorld w(threads);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-5, 5), yaw(-M_PI, M_PI);
  for (int k = 0; k < 10; ++k)
    w.scene().AddShape("pillar", {}, {{u(rng), u(rng), 0.2}, {}}, Cylinder(0.1, 0.4));
  std::vector<ObjectId> cameras;
  const Vec3 colors[3] = {kRed, kGreen, kBlue};
  for (int i = 0; i < 300; ++i) {
    BlobCameraRow row;
    row.range = 1.5;
    if (i % 4 == 0) row.fov = M_PI / 3;
    const ObjectId camera = w.CameraRobot(u(rng), u(rng), yaw(rng), row);
    w.Led(w.scene().parent(camera), {0, 0, i % 2 == 0 ? 0.083 : 0.0}, colors[i % 3]);
    cameras.push_back(camera);
  }
  w.world().Step();
  std::vector<std::vector<Blob>> out;
  for (ObjectId c : cameras) out.push_back(w.Blobs(c));
  return out;
}

TEST(BlobCameraTest, ReadingsAreTheSameAtOneAndTwoThreads) {
  const auto one = SwarmReadings(1);
  const auto two = SwarmReadings(2);
  ASSERT_EQ(one.size(), two.size());
  size_t seen = 0;
  for (size_t c = 0; c < one.size(); ++c) {
    ASSERT_EQ(one[c].size(), two[c].size()) << c;
    for (size_t b = 0; b < one[c].size(); ++b) {
      EXPECT_EQ(one[c][b].led, two[c][b].led);
      EXPECT_EQ(one[c][b].bearing, two[c][b].bearing);
      EXPECT_EQ(one[c][b].distance, two[c][b].distance);
      EXPECT_EQ(one[c][b].elevation, two[c][b].elevation);
      EXPECT_EQ(one[c][b].color, two[c][b].color);
    }
    seen += one[c].size();
  }
  EXPECT_GT(seen, 1000u);  // about 8 LEDs within 1.5 m of each camera
}

}  // namespace
}  // namespace swarmsim
