// What the range-and-bearing tests build on: foot-bot-sized robots with a
// board each, placed by hand in a World built in code (kinematic physics:
// nothing moves), and the readings of a board.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/range_and_bearing/range_and_bearing.h"

namespace swarmsim::range_and_bearing {

// One reading with its payload as a string.
struct Heard {
  std::string data;
  double range, bearing, elevation;
  ObjectId sender;
};

class RabWorld {
 public:
  static constexpr double kBodyCentre = 0.073;  // m above the ground
  static constexpr double kBoardUp = 0.05;      // m above the body's centre

  explicit RabWorld(int threads = 1, uint64_t seed = 1) {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = "kinematic";
    settings.threads = threads;
    settings.seed = seed;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log_.emplace_back(line); });
    EXPECT_TRUE(scene().FindType(kTypeName, &type_));
  }
  Scene& scene() { return world_->scene(); }
  World& world() { return *world_; }
  const std::vector<std::string>& log() const { return log_; }

  // A robot at (x, y) facing `yaw`: a cylinder body (r 0.085 m, 0.146 m
  // high, like a foot-bot's) with a board 0.05 m above its centre (+ dz).
  // Returns the board.
  ObjectId Robot(double x, double y, double yaw, const RangeAndBearingSettings& settings,
                 double dz = 0) {
    const std::string name = "bot#" + std::to_string(scene().instances().size());
    ShapeData body;
    body.kind = ShapeKind::kCylinder;
    body.size = {0.085, 0, 0.146};
    const ObjectId root =
        scene().AddShape(name, {}, {{x, y, kBodyCentre}, Quat::FromYaw(yaw)}, body);
    scene().MakeModelInstance(root, "bot", name);
    RangeAndBearingRow row;
    row.settings = Shared<RangeAndBearingSettings>(settings);
    return scene().AddObject(type_, "rab", root, {{0, 0, kBoardUp + dz}, {}}, &row);
  }
  // Another board on the robot of `board`, `dz` above it.
  ObjectId SecondBoard(ObjectId board, const RangeAndBearingSettings& settings, double dz) {
    const uint32_t slot = scene().SlotOf(board);
    const ObjectId root = scene().IdAt(static_cast<uint32_t>(scene().parent_at(slot)));
    RangeAndBearingRow row;
    row.settings = Shared<RangeAndBearingSettings>(settings);
    return scene().AddObject(type_, "rab2", root, {{0, 0, kBoardUp + dz}, {}}, &row);
  }
  // A static box (a wall) of full extents `size` centred at p.
  void Wall(const Vec3& p, const Vec3& size) {
    ShapeData s;
    s.kind = ShapeKind::kBox;
    s.size = size;
    scene().AddShape("wall", {}, {p, {}}, s);
  }
  RangeAndBearingRow& Row(ObjectId board) {
    return scene().rows<RangeAndBearingRow>(type_).rows[scene().row_at(scene().SlotOf(board))];
  }
  void SetData(ObjectId board, const std::string& bytes) {
    Row(board).data.assign(bytes.begin(), bytes.end());
  }
  // Runs one step (starting the world first) and returns the board's readings.
  std::vector<Heard> Step(ObjectId board) {
    if (!world_->started()) world_->Start();
    world_->Step();
    return Readings(board);
  }
  std::vector<Heard> Readings(ObjectId board) {
    const RangeAndBearingRow& row = Row(board);
    std::vector<Heard> out;
    for (const RangeAndBearingReading& r : row.readings)
      out.push_back({std::string(reinterpret_cast<const char*>(row.received.data()) + r.data_offset,
                                 r.data_size),
                     r.range, r.bearing, r.elevation, r.sender});
    return out;
  }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  std::vector<std::string> log_;
  ObjectType type_{};
};

}  // namespace swarmsim::range_and_bearing
