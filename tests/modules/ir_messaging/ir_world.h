// What the IR messaging tests build on: Kilobot-sized robots (a dummy root
// 1 cm above the floor) with a transceiver each, placed by hand in a World
// built in code (kinematic physics: nothing moves); messages queued the way
// sim.sendIrMessage queues them, and what a transceiver heard.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/ir_messaging/ir_messaging.h"

namespace swarmsim::ir_messaging {

struct HeardMessage {
  std::string data;
  double distance;
  ObjectId sender;
};

class IrWorld {
 public:
  explicit IrWorld(int threads = 1, uint64_t seed = 1, double time_step = 1.0 / 32) {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = "kinematic";
    settings.threads = threads;
    settings.seed = seed;
    settings.time_step = time_step;
    world_ = std::make_unique<World>(settings, registry_);
    EXPECT_TRUE(scene().FindType(kTypeName, &type_));
  }
  Scene& scene() { return world_->scene(); }
  World& world() { return *world_; }

  // A robot at (x, y) with a transceiver 1 cm above the floor. Returns the transceiver.
  ObjectId Robot(double x, double y, const IrSettings& settings) {
    const std::string name = "bot#" + std::to_string(scene().instances().size());
    const ObjectId root = scene().AddDummy(name, {}, {{x, y, 0.01}, {}});
    scene().MakeModelInstance(root, "bot", name);
    IrTransceiverRow row;
    row.settings = Shared<IrSettings>(settings);
    return scene().AddObject(type_, "ir", root, {}, &row);
  }
  IrTransceiverRow& Row(ObjectId ir) {
    return scene().rows<IrTransceiverRow>(type_).rows[scene().row_at(scene().SlotOf(ir))];
  }
  // Queues `bytes` on `ir` for the next sense phase.
  void Send(ObjectId ir, const std::string& bytes) {
    IrTransceiverRow& row = Row(ir);
    row.outgoing.assign(bytes.begin(), bytes.end());
    row.queued = true;
  }
  // Runs one step (starting the world first).
  void Step() {
    if (!world_->started()) world_->Start();
    world_->Step();
  }
  bool Sent(ObjectId ir) { return Row(ir).sent; }
  std::vector<HeardMessage> Heard(ObjectId ir) {
    const IrTransceiverRow& row = Row(ir);
    std::vector<HeardMessage> out;
    for (const IrReceived& m : row.inbox)
      out.push_back({std::string(reinterpret_cast<const char*>(row.received.data()) + m.data_offset,
                                 m.data_size),
                     m.distance, m.sender});
    return out;
  }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  ObjectType type_{};
};

// The Kilobot's settings without noise.
inline IrSettings Exact() {
  IrSettings s;
  s.distance_noise = 0;
  return s;
}

}  // namespace swarmsim::ir_messaging
