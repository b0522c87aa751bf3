// The rendering module's object types (modules/rendering/objects.cc):
// camera, vision sensor and light keys read into rows with the errors a
// user gets, a vision sensor's copy rendering afresh, lenses scaling, and
// the lights that are on collected in scene order.
#include "modules/rendering/objects.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/modules/entry_reader.h"
#include "tests/modules/module_world.h"

namespace swarmsim::rendering {
namespace {

using testing::EntryReader;
using testing::ErrorOf;
using testing::ModuleWorld;

template <typename Row>
std::string ReadError(const char* type, const EntryReader& entry) {
  ModuleWorld w;
  Row row;
  return ErrorOf([&] { testing::ReadRow(w.scene(), type, entry, &row); });
}

TEST(RenderingObjectsTest, ReadsALensAndAVisionSensorsKeys) {
  ModuleWorld w;
  EntryReader entry;
  entry.numbers["resolution"] = {320, 240};
  entry.strings["projection"] = {"orthographic"};
  entry.numbers["ortho_width"] = {4};
  entry.numbers["near"] = {0.5};
  entry.numbers["far"] = {30};
  entry.numbers["rate"] = {5};
  entry.numbers["depth"] = {0};
  entry.numbers["background"] = {1, 1, 0};
  entry.numbers["floor"] = {0};
  entry.strings["detectable"] = {":/parts"};
  VisionSensorRow v;
  testing::ReadRow(w.scene(), "vision_sensor", entry, &v);
  EXPECT_EQ(v.lens.width, 320);
  EXPECT_EQ(v.lens.height, 240);
  EXPECT_TRUE(v.lens.orthographic);
  EXPECT_DOUBLE_EQ(v.lens.ortho_width, 4);
  EXPECT_DOUBLE_EQ(v.lens.near, 0.5);
  EXPECT_DOUBLE_EQ(v.lens.far, 30);
  EXPECT_DOUBLE_EQ(v.rate, 5);
  EXPECT_FALSE(v.depth);
  EXPECT_EQ(v.background, (Vec3{1, 1, 0}));
  EXPECT_FALSE(v.floor);
  EXPECT_EQ(v.detectable, ":/parts");
  EXPECT_EQ(v.where, "entry.detectable");

  EntryReader camera;
  camera.numbers["fov_deg"] = {90};
  CameraRow c;
  testing::ReadRow(w.scene(), "camera", camera, &c);
  EXPECT_NEAR(c.lens.fov, M_PI / 2, 1e-15);
  EXPECT_EQ(c.lens.width, 640);  // a camera's own default
}

TEST(RenderingObjectsTest, BadLensesAreErrorsNamingTheKey) {
  EntryReader resolution;
  resolution.numbers["resolution"] = {320.5, 240};
  EXPECT_CONTAINS(ReadError<CameraRow>("camera", resolution),
                  "entry.resolution: each side of 'resolution' is a whole number of pixels from 1 "
                  "to 8192");
  resolution.numbers["resolution"] = {9000, 240};
  EXPECT_CONTAINS(ReadError<CameraRow>("camera", resolution), "from 1 to 8192");
  EntryReader fov;
  fov.numbers["fov_deg"] = {180};
  EXPECT_CONTAINS(ReadError<CameraRow>("camera", fov),
                  "entry.fov_deg: 'fov_deg' is more than 0 and less than 180");
  EntryReader clipping;
  clipping.numbers["near"] = {2};
  clipping.numbers["far"] = {1};
  EXPECT_CONTAINS(ReadError<VisionSensorRow>("vision_sensor", clipping),
                  "entry.far: 'far' (1.000000) must be more than 'near' (2.000000)");
  EntryReader near_only;  // a vision sensor's far is 10 m by default
  near_only.numbers["near"] = {20};
  EXPECT_CONTAINS(ReadError<VisionSensorRow>("vision_sensor", near_only), "entry.near:");
  EntryReader detectable;
  detectable.strings["detectable"] = {"environment"};
  EXPECT_CONTAINS(ReadError<VisionSensorRow>("vision_sensor", detectable),
                  "entry.detectable: 'detectable' is an object path or a collection");
  EntryReader projection;
  projection.strings["projection"] = {"fisheye"};
  EXPECT_CONTAINS(ReadError<CameraRow>("camera", projection),
                  "entry.projection: unknown 'fisheye'");
}

TEST(RenderingObjectsTest, ReadsALightsKeysAndRefusesBadOnes) {
  ModuleWorld w;
  EntryReader spot;
  spot.strings["kind"] = {"spot"};
  spot.numbers["cutoff_deg"] = {45};
  spot.numbers["exponent"] = {8};
  spot.numbers["range"] = {3};
  spot.numbers["color"] = {1, 0.5, 0};
  spot.numbers["on"] = {0};
  LightRow l;
  testing::ReadRow(w.scene(), "light", spot, &l);
  EXPECT_EQ(l.kind, LightSource::kSpot);
  EXPECT_NEAR(l.cutoff, M_PI / 4, 1e-15);
  EXPECT_DOUBLE_EQ(l.exponent, 8);
  EXPECT_DOUBLE_EQ(l.range, 3);
  EXPECT_FALSE(l.on);
  EntryReader cutoff;
  cutoff.numbers["cutoff_deg"] = {91};
  EXPECT_CONTAINS(ReadError<LightRow>("light", cutoff),
                  "entry.cutoff_deg: 'cutoff_deg' is more than 0 and at most 90");
  EntryReader exponent;
  exponent.numbers["exponent"] = {129};
  EXPECT_CONTAINS(ReadError<LightRow>("light", exponent),
                  "entry.exponent: 'exponent' is at most 128");
}

// A copy of a robot's vision sensor has the settings and no image yet;
// scaling the model scales the lens's lengths, not its pixels.
TEST(RenderingObjectsTest, ACopyRendersAfreshAndLensesScale) {
  ModuleWorld w;
  const ObjectId model = w.scene().AddDummy("model", {}, {});
  VisionSensorRow eye;
  eye.lens.ortho_width = 2;
  eye.lens.near = 0.1;
  eye.lens.far = 5;
  eye.rate = 4;
  eye.rendered_step = 12;
  eye.image.Resize(8, 8);
  w.Add("vision_sensor", "eye", model, {}, &eye);
  const ObjectId copy = w.scene().DuplicateSubtree(model, {});
  const ObjectId copied = w.scene().children(copy).at(0);
  const VisionSensorRow& c = w.RowOf<VisionSensorRow>("vision_sensor", copied);
  EXPECT_EQ(c.rendered_step, -1);
  EXPECT_EQ(c.image.width, 0);
  EXPECT_DOUBLE_EQ(c.rate, 4);
  w.scene().ScaleSubtree(copy, 2);
  const Lens& lens = w.RowOf<VisionSensorRow>("vision_sensor", copied).lens;
  EXPECT_DOUBLE_EQ(lens.ortho_width, 4);
  EXPECT_DOUBLE_EQ(lens.near, 0.2);
  EXPECT_DOUBLE_EQ(lens.far, 10);
  EXPECT_EQ(lens.width, 64);
}

TEST(RenderingObjectsTest, CollectLightsTakesTheLightsThatAreOnInSceneOrder) {
  ModuleWorld w;
  std::vector<LightSource> lights;
  bool any = true;
  CollectLights(w.scene(), &lights, &any);
  EXPECT_FALSE(any);
  EXPECT_TRUE(lights.empty());
  LightRow point;
  point.kind = LightSource::kPoint;
  point.color = {1, 0, 0};
  w.Add("light", "a", {}, {{1, 2, 3}, {}}, &point);
  LightRow off;
  off.on = false;
  w.Add("light", "b", {}, {}, &off);
  LightRow sun;
  w.Add("light", "c", {}, {{0, 0, 9}, Quat::FromAxisAngle({0, 1, 0}, M_PI / 2)}, &sun);
  w.scene().UpdateWorldPoses();
  CollectLights(w.scene(), &lights, &any);
  EXPECT_TRUE(any);
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0].kind, LightSource::kPoint);
  EXPECT_EQ(lights[0].position, (Vec3{1, 2, 3}));
  EXPECT_EQ(lights[0].color, (Vec3{1, 0, 0}));
  EXPECT_EQ(lights[1].kind, LightSource::kDirectional);
  EXPECT_NEAR(lights[1].direction.z, -1, 1e-12);  // along its +x: pitched down
}

}  // namespace
}  // namespace swarmsim::rendering
