// Range messages with line of sight: messaging.cc asks the proximity
// module whether a static shape hides the receiver. The rest of this file's
// tests moved to the files of the units they test (lua_api_control_test,
// script_hooks_test, script_state_test, script_hints_test, messaging_test,
// lua_api_messages_test, lua_api_custom_data_test, state_hash_test); this
// one follows line of sight when it leaves the proximity module.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/line_of_sight.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using namespace script_test;  // script_world.h

using testing::ErrorOf;

// --- Messages ------------------------------------------------------------------------------

// A robot that sends what `send` says in step 0 and prints everything it receives.
std::string Receiver(const std::string& send) {
  return R"(
    function sysCall_actuation()
      if sim.getSimulationTime() == 0 then )" +
         send + R"( end
      while true do
        local data, sender, distance, bearing = sim.receiveMessage()
        if not data then break end
        print(data, sim.getObjectName(sim.getObjectParent(sender)),
              distance and string.format('%.2f %.2f', distance, bearing) or '-')
      end
    end
  )";
}

TEST(ScriptControlTest, RangeMessagesHonourRangeAndLineOfSight) {
  // A module that provides the world's line of sight (framework/line_of_sight.h,
  // as the proximity module does) in which the segment crossing x = 0.5 is blocked.
  class Wall final : public Module, public LineOfSight {
   public:
    void Start(World* world) override { world->set_line_of_sight(this); }
    bool SegmentBlocked(const Vec3& a, const Vec3& b) const override {
      return (a.x - 0.5) * (b.x - 0.5) < 0;
    }
  };
  ModuleRegistry walled;
  walled.RegisterDynamics({"", "null", "1", ""}, {.substeps = false},
                          [] { return std::make_unique<testing::NullDynamics>(); });
  walled.RegisterModule(
      {{"sensor", "wall", "1", ""},
       PhaseBit(Phase::kSense),
       100,
       /*every_world=*/true,
       [](World*, const void*) -> std::unique_ptr<Module> { return std::make_unique<Wall>(); }});
  ScriptWorld w(1, {}, std::move(walled));
  w.AddRobot("s", Receiver("sim.sendRangeMessage('open', 2); sim.sendRangeMessage('los', 2, true)"),
             0, 0);
  w.AddRobot("near", Receiver(""), 0, 1.9);
  w.AddRobot("behind", Receiver(""), 1, 0);
  w.AddRobot("far", Receiver(""), 0, -2.1);
  w.Steps(2);
  const std::vector<std::string> expected = {
      "[near] open\ts\t1.90 -1.57", "[near] los\ts\t1.90 -1.57", "[behind] open\ts\t1.00 3.14"};
  EXPECT_EQ(w.log, expected);
}

}  // namespace
}  // namespace swarmsim
