// Snapshots of the swarm devices (framework/world_state.h): robots with a
// range-and-bearing board, an IR transceiver, a light sensor and a light, an
// LED and a blob camera, a ground sensor and a paint nozzle
// (tests/data/worlds/snapshot_devices.yaml), driven between steps as a
// Python controller drives them (wheels, RAB payloads, IR messages, LED
// colours, the lamp's intensity). Restore into a fresh world + k steps gives
// the uninterrupted run's state hash AND every reading a controller sees
// (what the Python arrays copy out of these rows) AND the paint layer's
// pixels, which the state hash does not hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "framework/floor_layer.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "modules/ground_sensor/ground_sensor.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "modules/light/light.h"
#include "modules/range_and_bearing/range_and_bearing.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim {
namespace {

const ModuleRegistry& Registry() {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    RegisterBuiltinModules(&r);
    return r;
  }();
  return registry;
}

LoadedWorld Load(const std::string& physics, int threads) {
  LoadOptions options;
  options.overrides = {{"physics", physics}};
  options.threads = threads;
  return LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/tests/data/worlds/snapshot_devices.yaml",
                   options, Registry());
}

template <class Row>
std::vector<Row>& RowsOf(Scene* scene, const char* type_name) {
  ObjectType type;
  EXPECT_TRUE(scene->FindType(type_name, &type)) << type_name;
  return scene->rows<Row>(type).rows;
}

// What a controller does between steps, from the step and each robot's
// index only: wheels, what each board sends, an IR message from every
// other robot every other step, LED colours, the lamp's intensity.
void Drive(World* world) {
  Scene& scene = world->scene();
  const int64_t step = world->step_count();
  for (size_t r = 0; r < scene.joints().size(); ++r) {
    const uint32_t slot = scene.joint_owners()[r];
    const int robot = scene.instance_of_at(slot);
    const bool left = scene.name_at(slot) == "leftMotor";
    const int64_t mode = (robot + step / 6) % 3;
    scene.joints()[r].target_velocity = mode == 0 ? 4.0 : (mode == 1) == left ? 4.0 : -2.0;
  }
  auto& boards = RowsOf<range_and_bearing::RangeAndBearingRow>(&scene, "range_and_bearing");
  for (size_t r = 0; r < boards.size(); ++r)
    boards[r].data = {uint8_t(r), uint8_t(step), uint8_t(step * r)};
  auto& irs = RowsOf<ir_messaging::IrTransceiverRow>(&scene, "ir_transceiver");
  for (size_t r = 0; r < irs.size(); ++r)
    if ((r + step) % 2 == 0) {
      irs[r].outgoing = {uint8_t(r), uint8_t(step)};
      irs[r].queued = true;
    }
  auto& leds = RowsOf<LedRow>(&scene, kLedTypeName);
  for (size_t r = 0; r < leds.size(); ++r) {
    const int64_t c = (int64_t(r) + step / 4) % 3;
    leds[r].color = {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0};
    leds[r].on = (r + step) % 5 != 0;
  }
  auto& lights = RowsOf<light::LightSourceRow>(&scene, light::kLightSourceTypeName);
  for (size_t r = 0; r < lights.size(); ++r)
    lights[r].intensity = 0.2 + 0.1 * double((r + step) % 7);
}

void StepDriven(World* world, int64_t until) {
  while (world->step_count() < until) {
    Drive(world);
    world->Step();
  }
}

// Every reading a controller sees, as numbers: each board's readings and
// payloads, each transceiver's inbox and `sent`, the light sensors, the
// blob cameras, the ground sensors, and the paint layer's pixels.
std::vector<double> Readings(World* world) {
  Scene& scene = world->scene();
  std::vector<double> out;
  for (const auto& b : RowsOf<range_and_bearing::RangeAndBearingRow>(&scene, "range_and_bearing")) {
    out.push_back(-1);  // a separator: counts matter too
    for (const auto& r : b.readings)
      out.insert(out.end(), {r.range, r.bearing, r.elevation, double(r.sender.index1)});
    out.insert(out.end(), b.received.begin(), b.received.end());
  }
  for (const auto& ir : RowsOf<ir_messaging::IrTransceiverRow>(&scene, "ir_transceiver")) {
    out.push_back(ir.sent ? -2 : -3);
    for (const auto& m : ir.inbox) out.insert(out.end(), {m.distance, double(m.sender.index1)});
    out.insert(out.end(), ir.received.begin(), ir.received.end());
  }
  for (const auto& l : RowsOf<light::LightSensorRow>(&scene, light::kLightSensorTypeName))
    out.push_back(l.reading);
  for (const auto& c : RowsOf<BlobCameraRow>(&scene, kBlobCameraTypeName)) {
    out.push_back(-4);
    for (const Blob& b : c.blobs)
      out.insert(out.end(), {b.color.x, b.color.y, b.color.z, b.distance, b.bearing, b.elevation});
  }
  for (const auto& g : RowsOf<ground_sensor::GroundSensorRow>(&scene, ground_sensor::kTypeName))
    out.push_back(g.value);
  const FloorLayer* floor = world->floor_layer();
  EXPECT_NE(floor, nullptr);
  if (floor != nullptr) {
    const std::span<const uint8_t> rgb = floor->floor_rgb();
    out.insert(out.end(), rgb.begin(), rgb.end());
  }
  return out;
}

// How much of it is not trivial: readings heard, messages received, paint.
struct Activity {
  size_t rab = 0, ir = 0, blobs = 0, painted = 0;
};
Activity ActivityOf(World* world) {
  Scene& scene = world->scene();
  Activity a;
  for (const auto& b : RowsOf<range_and_bearing::RangeAndBearingRow>(&scene, "range_and_bearing"))
    a.rab += b.readings.size();
  for (const auto& ir : RowsOf<ir_messaging::IrTransceiverRow>(&scene, "ir_transceiver"))
    a.ir += ir.inbox.size();
  for (const auto& c : RowsOf<BlobCameraRow>(&scene, kBlobCameraTypeName))
    a.blobs += c.blobs.size();
  // Pixels in the nozzles' colour, (0.9, 0.1, 0.1) as bytes.
  const std::span<const uint8_t> rgb = world->floor_layer()->floor_rgb();
  for (size_t p = 0; p + 2 < rgb.size(); p += 3)
    a.painted += rgb[p] == 230 && rgb[p + 1] == 26 && rgb[p + 2] == 26;
  return a;
}

class SnapshotDevicesTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SnapshotDevicesTest, RestorePlusStepsGivesTheSameHashAndReadings) {
  for (const int64_t at : {0, 9}) {
    LoadedWorld original = Load(GetParam(), 2);
    StepDriven(original.world.get(), at);
    const std::string bytes = original.world->SaveState();
    const uint64_t at_hash = original.world->StateHash();
    const std::vector<double> at_readings = Readings(original.world.get());
    std::vector<uint64_t> hashes;
    std::vector<std::vector<double>> readings;
    for (const int64_t later : {at + 1, at + 7, at + 20}) {
      StepDriven(original.world.get(), later);
      hashes.push_back(original.world->StateHash());
      readings.push_back(Readings(original.world.get()));
    }
    // The run exercises every device.
    const Activity activity = ActivityOf(original.world.get());
    EXPECT_GT(activity.rab, 0u);
    EXPECT_GT(activity.ir, 0u);
    EXPECT_GT(activity.blobs, 0u);
    EXPECT_GT(activity.painted, 20u);
    EXPECT_NE(readings[1], readings[2]);

    LoadedWorld restored = Load(GetParam(), at == 0 ? 1 : 2);  // any thread count
    restored.world->RestoreState(bytes);
    EXPECT_EQ(restored.world->StateHash(), at_hash) << "restored at " << at;
    EXPECT_EQ(Readings(restored.world.get()), at_readings) << "restored at " << at;
    for (size_t k = 0; k < hashes.size(); ++k) {
      StepDriven(restored.world.get(), at + (k == 0 ? 1 : k == 1 ? 7 : 20));
      EXPECT_EQ(restored.world->StateHash(), hashes[k]) << "restored at " << at << ", k " << k;
      EXPECT_EQ(Readings(restored.world.get()), readings[k]) << "restored at " << at << ", k " << k;
    }
    // The original goes back too: the paint of the steps after the snapshot
    // is gone from its layer.
    original.world->RestoreState(bytes);
    EXPECT_EQ(Readings(original.world.get()), at_readings);
    StepDriven(original.world.get(), at + 20);
    EXPECT_EQ(original.world->StateHash(), hashes[2]);
    EXPECT_EQ(Readings(original.world.get()), readings[2]);
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, SnapshotDevicesTest, ::testing::Values("kinematic", "box2d"));

// A snapshot's readings are the world's own: a restored world whose rows
// were emptied gets them back (not a fresh sense phase's).
TEST(SnapshotDevicesTest, RestoringGivesBackTheReadingsOfTheSnapshotNotFreshOnes) {
  LoadedWorld original = Load("kinematic", 2);
  StepDriven(original.world.get(), 5);
  const std::string bytes = original.world->SaveState();
  const std::vector<double> readings = Readings(original.world.get());
  LoadedWorld other = Load("kinematic", 2);
  StepDriven(other.world.get(), 11);
  ASSERT_NE(Readings(other.world.get()), readings);
  other.world->RestoreState(bytes);
  EXPECT_EQ(Readings(other.world.get()), readings);
  EXPECT_EQ(other.world->step_count(), 5);
}

}  // namespace
}  // namespace swarmsim
