// The `led` and `blob_camera` object types (modules/blobs/objects.cc):
// their keys read into rows with the errors a user gets, copies of a camera
// seeing afresh, scaling, and an LED's colour in the state hash.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

std::string CameraError(const EntryReader& entry) {
  ModuleWorld w;
  BlobCameraRow row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), kBlobCameraTypeName, entry, &row); });
}

TEST(BlobsObjectsTest, ReadsAnLedsKeys) {
  ModuleWorld w;
  EntryReader entry;
  entry.numbers["color"] = {0, 0.5, 1};
  entry.numbers["on"] = {0};
  entry.numbers["radius"] = {0.02};
  LedRow led;
  testing::ReadRow(w.scene(), kLedTypeName, entry, &led);
  EXPECT_EQ(led.color, (Vec3{0, 0.5, 1}));
  EXPECT_FALSE(led.on);
  EXPECT_DOUBLE_EQ(led.radius, 0.02);
  EXPECT_FALSE(led.lit());
  entry.numbers["color"] = {0, 1.5, 0};
  EXPECT_CONTAINS(ErrorOf([&] { testing::ReadRow(w.scene(), kLedTypeName, entry, &led); }),
                  "entry.color: must be a number from 0 to 1");
}

TEST(BlobsObjectsTest, ReadsACamerasKeysInDegrees) {
  ModuleWorld w;
  EntryReader entry;
  entry.numbers["range"] = {2.5};
  entry.numbers["fov_deg"] = {90};
  entry.numbers["vertical_fov_deg"] = {30};
  entry.numbers["occlusion"] = {0};
  entry.numbers["angle_noise_deg"] = {2};
  entry.numbers["distance_noise"] = {0.1};
  entry.numbers["enabled"] = {0};
  BlobCameraRow c;
  testing::ReadRow(w.scene(), kBlobCameraTypeName, entry, &c);
  EXPECT_DOUBLE_EQ(c.range, 2.5);
  EXPECT_NEAR(c.fov, M_PI / 2, 1e-15);
  EXPECT_NEAR(c.vertical_fov, M_PI / 6, 1e-15);
  EXPECT_FALSE(c.occlusion);
  EXPECT_NEAR(c.angle_noise, 2 * M_PI / 180, 1e-15);
  EXPECT_DOUBLE_EQ(c.distance_noise, 0.1);
  EXPECT_FALSE(c.enabled);
}

TEST(BlobsObjectsTest, AperturesOutOfRangeAreErrors) {
  EntryReader fov;
  fov.numbers["fov_deg"] = {361};
  EXPECT_CONTAINS(CameraError(fov),
                  "entry.fov_deg: 'fov_deg' must be an angle above 0 and up to 360 degrees (got "
                  "361)");
  fov.numbers["fov_deg"] = {360};
  EXPECT_EQ(CameraError(fov), "");
  EntryReader vertical;
  vertical.numbers["vertical_fov_deg"] = {0};
  EXPECT_CONTAINS(CameraError(vertical),
                  "'vertical_fov_deg' must be an angle above 0 and up to 180 degrees (got 0)");
  EntryReader noise;
  noise.numbers["angle_noise_deg"] = {91};
  EXPECT_CONTAINS(CameraError(noise), "entry.angle_noise_deg: must be an angle from 0 to 90");
  EntryReader range;
  range.numbers["range"] = {-1};
  EXPECT_CONTAINS(CameraError(range), "entry.range: must be a positive number");
}

// A copy of a robot's camera sees afresh; scaling a model scales a camera's
// range (and what it saw) and an LED's size.
TEST(BlobsObjectsTest, CopiesSeeAfreshAndScalingScalesLengths) {
  ModuleWorld w;
  const ObjectId model = w.scene().AddDummy("model", {}, {});
  BlobCameraRow camera;
  camera.range = 2;
  camera.blobs.push_back({{1, 0, 0}, 1.5, 0, 0, {}});
  const ObjectId cam = w.Add(kBlobCameraTypeName, "camera", model, {}, &camera);
  LedRow led;
  led.radius = 0.01;
  w.Add(kLedTypeName, "led", model, {}, &led);
  const ObjectId copy = w.scene().DuplicateSubtree(model, {});
  const ObjectId copied_cam = w.scene().children(copy).at(0);
  const ObjectId copied_led = w.scene().children(copy).at(1);
  EXPECT_TRUE(w.RowOf<BlobCameraRow>(kBlobCameraTypeName, copied_cam).blobs.empty());
  EXPECT_DOUBLE_EQ(w.RowOf<BlobCameraRow>(kBlobCameraTypeName, copied_cam).range, 2);
  w.scene().ScaleSubtree(model, 3);
  const BlobCameraRow& scaled = w.RowOf<BlobCameraRow>(kBlobCameraTypeName, cam);
  EXPECT_DOUBLE_EQ(scaled.range, 6);
  ASSERT_EQ(scaled.blobs.size(), 1u);
  EXPECT_DOUBLE_EQ(scaled.blobs[0].distance, 4.5);
  EXPECT_DOUBLE_EQ(w.RowOf<LedRow>(kLedTypeName, copied_led).radius, 0.01);  // not the copy's
}

TEST(BlobsObjectsTest, AnLedsColourIsInTheStateHash) {
  ModuleWorld w;
  const ObjectId bot = w.Robot("bot", {});
  LedRow led;
  const ObjectId id = w.Add(kLedTypeName, "led", bot, {}, &led);
  ASSERT_EQ(w.Run(0), "");
  const uint64_t white = w.world().StateHash();
  w.RowOf<LedRow>(kLedTypeName, id).color = {1, 0, 0};
  const uint64_t red = w.world().StateHash();
  EXPECT_NE(red, white);
  w.RowOf<LedRow>(kLedTypeName, id).on = false;
  EXPECT_NE(w.world().StateHash(), red);
}

}  // namespace
}  // namespace swarmsim
