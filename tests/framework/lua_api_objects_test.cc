// sim.* objects (framework/lua_api_objects.cc): lookup by path from the
// calling script (so copies of a model find their own objects), indexed
// names, suggestions for a missing path, stale handles, and poses in the
// world and relative frames.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "modules/proximity/proximity_sensor.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"
#include "tests/framework/script_world.h"

namespace swarmsim {
namespace {

using script_test::ScriptWorld;
using script_test::Source;

using testing::ErrorOf;

TEST(ScriptHostTest, StaleHandleIsAnError) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0", R"(
    function sysCall_init() eye = sim.getObject('./eye') end
    function sysCall_actuation() sim.getObjectPose(eye) end
  )",
                    "scripts/stale.lua");
  const ObjectId eye = w.scene().AddDummy("eye", w.scene().FindObject("/bot#0/body"), {});
  w.world().Start();
  w.world().Step();
  w.scene().RemoveSubtree(eye);
  EXPECT_CONTAINS(ErrorOf([&] { w.world().Step(); }),
                  "scripts/stale.lua:3: sim.getObjectPose: "
                  "object handle " +
                      std::to_string(eye.ToInteger()) + " is stale");
}

TEST(ScriptHostTest, DuplicatedModelsFindTheirOwnObjects) {
  ScriptWorld w;
  const ObjectId body = w.AddWheeledRobot("bot#0", R"(
    local left, right, me
    function sysCall_init()
      left = sim.getObject('./leftMotor')
      right = sim.getObject(':/rightMotor')
      me = sim.getObject('.')
      assert(sim.getObject('./motor', {noError = true}) == -1)
      assert(sim.getObjectParent(left) == me)
      assert(sim.getObjectParent(sim.getObjectParent(me)) == -1)
    end
    function sysCall_actuation()
      sim.setJointTargetVelocity(left, sim.getRobotIndex() + 1)
      sim.setJointTargetVelocity(right, -(sim.getRobotIndex() + 1))
    end
  )");
  const ObjectId root = w.scene().parent(body);
  w.scene().DuplicateSubtree(root, {});
  w.scene().DuplicateSubtree(root, {});
  ASSERT_EQ(w.world().robot_count(), 3);
  w.world().Step();
  for (int r = 0; r < 3; ++r) {
    const ObjectId root = w.scene().instance(r).root;
    EXPECT_EQ(w.scene().joint(w.scene().FindObject("./body/leftMotor", root)).velocity, r + 1.0);
    EXPECT_EQ(w.scene().joint(w.scene().FindObject("./body/rightMotor", root)).velocity,
              -(r + 1.0));
  }
}

TEST(ScriptHostTest, RepeatedNamesAreIndexed) {
  ScriptWorld w;
  const ObjectId body = w.AddWheeledRobot("bot#0", R"(
    function sysCall_init()
      for i = 0, 2 do
        local h = sim.getObject('./prox[' .. i .. ']')
        print(sim.getObjectName(h), sim.getObjectPosition(h, sim.getObject('.'))[2])
      end
      print(sim.getObject('./prox[3]', {noError = true}))
    end
  )");
  for (int i = 0; i < 3; ++i)
    proximity::AddSensor(&w.scene(), "prox", body, {{0, 0.5 * i, 0}, {}}, {});
  w.world().Start();
  const std::vector<std::string> expected = {"[bot#0] prox\t0.0", "[bot#0] prox\t0.5",
                                             "[bot#0] prox\t1.0", "[bot#0] -1"};
  EXPECT_EQ(w.log, expected);
}

TEST(ScriptHostTest, MissingObjectPathSuggestsTheNearestNameOrTheIndexRange) {
  // path -> what the error must say, for a script on /bot#0/body (joints
  // leftMotor and rightMotor, 12 sensors 'prox').
  const std::pair<std::string, std::string> cases[] = {
      {"./leftmotor",
       "no object at path './leftmotor' (looked up from /bot#0/body); did you mean "
       "'./leftMotor'?"},
      {"./prox[12]",
       "no object at path './prox[12]' (looked up from /bot#0/body); there are 12 objects named "
       "'prox' there: prox[0]..prox[11]"},
      {":/body/rigthMotor", "; did you mean ':/body/rightMotor'?"},
      {"/bot#0/bdy/leftMotor", "; did you mean '/bot#0/body/leftMotor'?"},
      {"./wheel",
       "no object at path './wheel' (looked up from /bot#0/body); the names there: "
       "leftMotor, prox, rightMotor"},
  };
  for (const auto& [path, message] : cases) {
    ScriptWorld w;
    const ObjectId body =
        w.AddWheeledRobot("bot#0", "function sysCall_init() sim.getObject('" + path + "') end");
    for (int i = 0; i < 12; ++i) proximity::AddSensor(&w.scene(), "prox", body, {}, {});
    EXPECT_CONTAINS(ErrorOf([&] { w.world().Start(); }), message);
  }
  // A nearest name whose path names nothing either is not suggested: bot#0
  // has no 'eye', so '/bot#0/body/eye' would be a second dead end.
  ScriptWorld w;
  w.AddWheeledRobot("bot#0", "function sysCall_init() sim.getObject('/bot#9/body/eye') end");
  const std::string error = ErrorOf([&] { w.world().Start(); });
  EXPECT_CONTAINS(error, "no object at path '/bot#9/body/eye'");
  EXPECT_CONTAINS(error, "; the names there: bot#0");
  EXPECT_EQ(error.find("did you mean"), std::string::npos) << error;
}

TEST(ScriptHostTest, PosesInWorldAndRelativeFrames) {
  ScriptWorld w;
  const ObjectId body = w.scene().AddDummy("base", {}, {{1, 2, 0}, Quat::FromYaw(M_PI / 2)});
  w.scene().AddDummy("tip", body, {{0.5, 0, 0.25}, {}});
  w.scene().MakeModelInstance(body, "arm", "arm#0");
  w.scene().AttachScript(body, Source("scripts/pose.lua", R"(
    function sysCall_init()
      local tip, me = sim.getObject('./tip'), sim.getObject('.')
      local function show(t) local s = {} for i, v in ipairs(t) do s[i] = string.format('%.3f', v) end return table.concat(s, ' ') end
      print(show(sim.getObjectPosition(tip)))
      print(show(sim.getObjectPosition(tip, me)))
      print(show(sim.getObjectPose(tip, sim.handle_world)))
      print(show(sim.getObjectOrientation(tip)))
      print(show(sim.getObjectOrientation(me, tip)))
    end
  )"));
  w.world().Start();
  const double h = std::sqrt(0.5);
  char pose[200];
  std::snprintf(pose, sizeof pose, "[arm#0] 1.000 2.500 0.250 0.000 0.000 %.3f %.3f", h, h);
  const std::vector<std::string> expected = {
      "[arm#0] 1.000 2.500 0.250", "[arm#0] 0.500 0.000 0.250", pose, "[arm#0] 0.000 0.000 1.571",
      "[arm#0] 0.000 0.000 0.000"};
  EXPECT_EQ(w.log, expected);
}

// sim.setObjectOrientation: getObjectOrientation's roll, pitch, yaw back
// (in the world, or relative to an object), the position kept; applied
// after the control phase like the other moves.
// A quaternion is any nonzero 4-vector, however large its components (its
// squared norm overflowed: the pose became a zero quaternion, or ODE
// stopped on an assertion); {0, 0, 0, 0} is refused.
TEST(ScriptHostTest, SetObjectPoseTakesAnyNonzeroQuaternion) {
  ScriptWorld w;
  w.AddWheeledRobot("bot#0", R"(
    function sysCall_actuation()
      local me = sim.getObject('.')
      if sim.getSimulationTime() == 0 then
        sim.setObjectPose(me, {0.5, 0, 0, 0, 0, 1e300, 1e300})
        print(pcall(sim.setObjectPose, me, {0, 0, 0, 0, 0, 0, 0}))
      else
        local p = sim.getObjectPose(me)
        print(string.format('%.6f %.6f %.6f %.6f', p[4], p[5], p[6], p[7]))
      end
    end
  )");
  w.world().Start();
  w.world().Step();
  w.world().Step();
  ASSERT_EQ(w.log.size(), 2u);
  EXPECT_CONTAINS(w.log[0], "false");
  EXPECT_CONTAINS(w.log[0],
                  "the quaternion {qx, qy, qz, qw} is {0, 0, 0, 0}, which is no rotation");
  EXPECT_EQ(w.log[1], "[bot#0] 0.000000 0.000000 0.707107 0.707107");  // 90 degrees about z
}

TEST(ScriptHostTest, SetObjectOrientationIsGetObjectOrientationsInverse) {
  ScriptWorld w;
  const ObjectId body = w.scene().AddDummy("base", {}, {{1, 2, 0}, Quat::FromYaw(M_PI / 2)});
  w.scene().AddDummy("tip", body, {{0.5, 0, 0.25}, {}});
  w.scene().MakeModelInstance(body, "arm", "arm#0");
  w.scene().AttachScript(body, Source("scripts/orient.lua", R"(
    local n = 0
    local function show(t)
      local s = {}
      for i, v in ipairs(t) do
        if math.abs(v) < 1e-12 then v = 0 end  -- rounding's -1e-17 is 0
        s[i] = string.format('%.6f', v)
      end
      return table.concat(s, ' ')
    end
    function sysCall_actuation()
      local tip, me = sim.getObject('./tip'), sim.getObject('.')
      if n == 0 then
        sim.setObjectOrientation(tip, {0.1, -0.2, 0.3})
        print('same step: ' .. show(sim.getObjectOrientation(tip)))
      elseif n == 1 then
        print(show(sim.getObjectOrientation(tip)))
        print(show(sim.getObjectPosition(tip)))
        sim.setObjectOrientation(tip, {0, 0, 0.5}, me)
      else
        print(show(sim.getObjectOrientation(tip, me)))
      end
      n = n + 1
    end
  )"));
  w.world().Start();
  for (int i = 0; i < 3; ++i) w.world().Step();
  const std::vector<std::string> expected = {
      "[arm#0] same step: 0.000000 0.000000 1.570796", "[arm#0] 0.100000 -0.200000 0.300000",
      "[arm#0] 1.000000 2.500000 0.250000", "[arm#0] 0.000000 0.000000 0.500000"};
  EXPECT_EQ(w.log, expected);
}

}  // namespace
}  // namespace swarmsim
