// The blob camera (modules/blobs: no rasterising) against a rendered camera
// (modules/rendering) through a threshold + blobs filter chain, from the
// same place over the same scene: the same LEDs, in the same directions,
// hidden by the same box (issue 14: "the same meaning as a rendered image
// through the blob filter").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/rendering/objects.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class BlobCameraVsRenderTest : public testing::WorldDirTest {};

constexpr char kScene[] = R"(simulation: {physics: kinematic}
objects:
  - {name: blobs, type: blob_camera, position: [0, 0, 0.3], range: 5}
  - name: camera
    type: vision_sensor
    position: [0, 0, 0.3]
    resolution: [320, 240]
    fov_deg: 90
    near: 0.05
    far: 6
    floor: false
    filters:
      - {type: hsv_threshold, saturation: [0.5, 1], value: [0.5, 1]}
      - {type: blobs}
  - {name: red, type: led, color: [1, 0, 0], radius: 0.03, position: [2, 0.5, 0.3]}
  - {name: green, type: led, color: [0, 1, 0], radius: 0.03, position: [1.5, -1.0, 0.45]}
  - {name: blue, type: led, color: [0, 0, 1], radius: 0.03, position: [3, 1.8, 0.15]}
  - {name: yellow, type: led, color: [1, 1, 0], radius: 0.03, position: [1, 0.3, 0.3]}
  # Behind a grey box: neither camera sees it.
  - {name: magenta, type: led, color: [1, 0, 1], radius: 0.03, position: [2.5, -0.2, 0.3]}
  - {name: wall, type: shape, shape: box, size: [0.1, 0.4, 0.6], position: [1.5, -0.12, 0.3],
     color: [0.5, 0.5, 0.5]}
  # Behind the rendered camera's field of view; the omnidirectional one sees it.
  - {name: cyan, type: led, color: [0, 1, 1], radius: 0.03, position: [-1, 1, 0.3]}
)";

double ColourDistance(const Vec3& a, const std::array<double, 3>& b) {
  return std::abs(a.x - b[0]) + std::abs(a.y - b[1]) + std::abs(a.z - b[2]);
}

TEST_F(BlobCameraVsRenderTest, BothSeeTheSameLedsInTheSameDirections) {
  LoadedWorld w = Load(kScene);
  w.world->Start();
  w.world->Step();  // both sense in the sense phase
  const auto& seen = RowOf<BlobCameraRow>(*w.world, "/blobs").blobs;
  const auto& sensor = RowOf<rendering::VisionSensorRow>(*w.world, "/camera");
  const auto& rendered = sensor.output.blobs;
  // The omnidirectional camera: five (not magenta); the rendered one: the
  // four in front of it.
  ASSERT_EQ(seen.size(), 5u);
  ASSERT_EQ(rendered.size(), 4u);
  const filters::CameraModel camera = rendering::CameraModelOf(sensor.lens);
  const double pixel = M_PI / 2 / 320;  // rad per pixel
  int matched = 0;
  for (const filters::Blob& r : rendered) {
    // The blob camera's blob of the nearest colour.
    const Blob* best = nullptr;
    for (const Blob& b : seen)
      if (best == nullptr ||
          ColourDistance(b.color, r.colour) < ColourDistance(best->color, r.colour))
        best = &b;
    ASSERT_LT(ColourDistance(best->color, r.colour), 0.1) << "a colour the blob camera saw";
    const Vec3 p = filters::ImageToSensor(camera, 320, 240, r.x, r.y, 1);
    const double bearing = std::atan2(p.y, p.x);
    const double elevation = std::atan2(p.z, std::hypot(p.x, p.y));
    EXPECT_NEAR(bearing, best->bearing, pixel)
        << "colour " << best->color.x << best->color.y << best->color.z;
    EXPECT_NEAR(elevation, best->elevation, pixel);
    ++matched;
  }
  EXPECT_EQ(matched, 4);
  // The one behind: only the omnidirectional camera, at bearing 135 degrees.
  bool behind = false;
  for (const Blob& b : seen) behind |= std::abs(b.bearing - 3 * M_PI / 4) < 1e-9;
  EXPECT_TRUE(behind);
}

}  // namespace
}  // namespace swarmsim
