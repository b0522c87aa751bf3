// sim.* joints (framework/lua_api_joints.cc): a robot writes its own joints
// at once and another robot's after the phase, in handle order; it cannot
// read another robot's targets.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using script_test::ScriptWorld;
using script_test::Source;

using testing::ErrorOf;

TEST(ScriptHostTest, WritesToAnotherRobotsJointAreDeferredToAfterThePhase) {
  ScriptWorld w;
  // bot#0 runs first (one thread) and writes bot#1's motor; bot#1 must not
  // see it during the same phase, but its own writes at once.
  w.AddWheeledRobot("bot#0", R"(
    function sysCall_sensing()
      sim.setJointTargetVelocity(sim.getObject('/bot#1/body/leftMotor'), 5)
    end
  )");
  w.AddWheeledRobot("bot#1", R"(
    local left, right
    function sysCall_init() left, right = sim.getObject('./leftMotor'), sim.getObject('./rightMotor') end
    function sysCall_actuation()
      sim.setJointTargetVelocity(right, 3)
      sim.recordMetric('left_target', sim.getJointTargetVelocity(left))
      sim.recordMetric('right_target', sim.getJointTargetVelocity(right))
      sim.recordMetric('left_velocity', sim.getJointVelocity(left))
    end
  )");
  w.world().Start();
  w.world().Step();
  auto metrics = w.world().TakeMetrics();
  ASSERT_EQ(metrics.size(), 3u);
  EXPECT_EQ(metrics[0].value, 0.0);  // not yet: deferred
  EXPECT_EQ(metrics[1].value, 3.0);  // own write: immediate
  EXPECT_EQ(metrics[2].value, 0.0);
  EXPECT_EQ(w.scene().joint(w.Joint("/bot#1/body/leftMotor")).target_velocity, 5.0);
  w.world().Step();
  metrics = w.world().TakeMetrics();
  ASSERT_EQ(metrics.size(), 3u);
  EXPECT_EQ(metrics[0].value, 5.0);  // applied after the first phase
  EXPECT_EQ(metrics[2].value, 5.0);
}

// A prismatic joint moved past the 1e6 m a world may use is refused at the
// call (it then "blew up the physics", naming no line); a revolute joint's
// angle has no such bound.
TEST(ScriptHostTest, PrismaticPositionsBeyondTheWorldAreRefused) {
  ScriptWorld w;
  const ObjectId body = w.AddWheeledRobot("bot#0", R"(
    function sysCall_actuation()
      local slide, hinge = sim.getObject('./slide'), sim.getObject('./leftMotor')
      print(pcall(sim.setJointPosition, slide, 1e7))
      print(pcall(sim.setJointTargetPosition, slide, -2e6))
      print(pcall(sim.setJointPosition, slide, 3))
      print(pcall(sim.setJointPosition, hinge, 1e7))
    end
  )");
  JointData slide;
  slide.settings.Edit().type = JointType::kPrismatic;
  w.scene().AddJoint("slide", body, {}, slide);
  w.world().Start();
  w.world().Step();
  ASSERT_EQ(w.log.size(), 4u);
  EXPECT_CONTAINS(w.log[0],
                  "sim.setJointPosition: the position 1e+07 moves the joint's children "
                  "1e+07 m, beyond the 1e6 m a world may use");
  EXPECT_CONTAINS(w.log[1], "sim.setJointTargetPosition: the target position -2e+06 moves");
  EXPECT_EQ(w.log[2], "[bot#0] true");
  EXPECT_EQ(w.log[3], "[bot#0] true");
}

TEST(ScriptHostTest, ReadingAnotherRobotsJointTargetIsAnError) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0",
                    "function sysCall_sensing()\n  "
                    "sim.getJointTargetVelocity(sim.getObject('/bot#1/body/leftMotor'))\nend",
                    "scripts/peek.lua");
  w.AddWheeledRobot("bot#1", "");
  w.world().Start();
  EXPECT_CONTAINS(ErrorOf([&] { w.world().Step(); }),
                  "scripts/peek.lua:2: sim.getJointTargetVelocity: joint '/bot#1/body/leftMotor' "
                  "belongs to another robot");
}

}  // namespace
}  // namespace swarmsim
