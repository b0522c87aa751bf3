// The scripts' side of modules/paths (lua_api_paths.cc): sim.getPathLength,
// sim.getPathPose, sim.getPathPosition, sim.setPathPosition,
// sim.setPathVelocity and sim.createPath, who may set what, and their
// errors.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "modules/paths/curve.h"
#include "modules/paths/rows.h"
#include "tests/framework/error_of.h"
#include "tests/modules/module_world.h"

namespace swarmsim::paths {
namespace {

using testing::ModuleWorld;

// A scene-level path "track" from (1, 0, 0) 2 m along +x in the world (its
// child "rider" follows it) and a robot "bot" at (0, 5, 0) with its own
// path "lane" 3 m along +y; `scene_code` runs on the track, `robot_code` on
// the robot. Returns the log after `steps` steps, the error in *error.
struct PathsScripts {
  ModuleWorld w;
  ObjectId track, rider, bot, lane;

  PathsScripts() {
    PathRow row;
    row.curve = std::make_shared<const PathCurve>(std::vector<Vec3>{{0, 0, 0}, {2, 0, 0}},
                                                  Interpolation::kLinear, false);
    row.followers = {"rider"};
    track = w.Add(kTypeName, "track", {}, {{1, 0, 0}, {}}, &row);
    rider = w.Box("rider", track, {}, {0.1, 0.1, 0.1});
    bot = w.Robot("bot", {{0, 5, 0}, {}});
    PathRow lane_row;
    lane_row.curve = std::make_shared<const PathCurve>(std::vector<Vec3>{{0, 0, 0}, {0, 3, 0}},
                                                       Interpolation::kLinear, false);
    lane = w.Add(kTypeName, "lane", bot, {}, &lane_row);
  }
  PathRow& row(ObjectId path) { return w.RowOf<PathRow>(kTypeName, path); }
  std::string Log() const {
    std::string all;
    for (const std::string& line : w.log()) all += line + "\n";
    return all;
  }
};

TEST(LuaApiPathsTest, ScriptsReadALengthAPoseAndThePosition) {
  PathsScripts s;
  s.w.Script(s.track, R"(
    function sysCall_init()
      local track = sim.getObject('/track')
      print(string.format('length %g via rider %g', sim.getPathLength(track),
                          sim.getPathLength(sim.getObject('/track/rider'))))
      local p = sim.getPathPose(track, 0.5)
      print(string.format('pose %g %g %g %g', p[1], p[2], p[3], p[7]))
      sim.setPathVelocity(track, 0.5)
    end
    function sysCall_sensing()
      print(string.format('at %g', sim.getPathPosition(sim.getObject('/track'))))
    end
  )");
  EXPECT_EQ(s.w.Run(4), "");
  const std::string log = s.Log();
  EXPECT_CONTAINS(log, "length 2 via rider 2");
  EXPECT_CONTAINS(log, "pose 1.5 0 0 1");  // the world frame: the track starts at x = 1
  // As of each step's start: the position moves in the actuate phase only.
  EXPECT_CONTAINS(log, "at 0\n");
  EXPECT_CONTAINS(log, "at 0.05\n");
  EXPECT_CONTAINS(log, "at 0.15\n");
  EXPECT_DOUBLE_EQ(s.row(s.track).velocity, 0.5);
}

TEST(LuaApiPathsTest, ASetPositionIsAppliedInTheActuatePhaseClampedToThePath) {
  PathsScripts s;
  s.w.Script(s.bot, R"(
    function sysCall_init()
      sim.setPathPosition(sim.getObject('./lane'), 10)
      print(string.format('before %g', sim.getPathPosition(sim.getObject('./lane'))))
    end
  )");
  EXPECT_EQ(s.w.Run(1), "");
  EXPECT_CONTAINS(s.Log(), "before 0");
  EXPECT_DOUBLE_EQ(s.row(s.lane).position, 3);
}

TEST(LuaApiPathsTest, ARobotSetsOnlyItsOwnPaths) {
  PathsScripts s;
  s.w.Script(s.bot,
             "function sysCall_init()\n  sim.setPathVelocity(sim.getObject('/track'), 1)\nend\n");
  EXPECT_CONTAINS(s.w.Run(1), "path '/track' belongs to another robot");
  EXPECT_DOUBLE_EQ(s.row(s.track).velocity, 0);
}

std::string ErrorOfScript(const std::string& line) {
  PathsScripts s;
  s.w.Script(s.bot, "function sysCall_init()\n" + line + "\nend\n");
  return s.w.Run(1);
}

TEST(LuaApiPathsTest, BadArgumentsAreErrorsNamingWhatIsWrong) {
  EXPECT_CONTAINS(ErrorOfScript("sim.getPathLength(sim.getObject('/bot'))"),
                  "object /bot is neither a path nor a path's child");
  EXPECT_CONTAINS(ErrorOfScript("sim.setPathVelocity(sim.getObject('./lane'), 0/0)"),
                  "the velocity is not a finite number");
  EXPECT_CONTAINS(ErrorOfScript("sim.getPathPose(sim.getObject('./lane'), math.huge)"),
                  "the arc length is not a finite number");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}})"), "at least 2 points");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {0, 0, 0}})"),
                  "point 2 repeats the one before");
  // Nearly repeated: its length was 0 and its poses NaN.
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1e-300, 0, 0}})"),
                  "point 2 is less than 1e-9 m from the one before");
  // A misspelt option was dropped without a word (the path never moved).
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}}, {velocty = 0.5})"),
                  "bad argument #2 (no option 'velocty'; did you mean 'velocity'?)");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}}, {0.5})"),
                  "options are named: a key that is not a string");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0}})"),
                  "point 2 needs three finite numbers of metres");
  EXPECT_CONTAINS(
      ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}, {0, 0, 0}}, {closed = true})"),
      "the last point repeats the first");
  EXPECT_CONTAINS(
      ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}}, {interpolation = 'curvy'})"),
      "options.interpolation: 'linear' or 'smooth' expected");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}}, {name = 'a/b'})"),
                  "options.name: a name without '/' expected");
  EXPECT_CONTAINS(ErrorOfScript("sim.createPath({{0, 0, 0}, {1, 0, 0}}, {parent = "
                                "sim.getObject('/track')})"),
                  "a robot's script makes paths under its own objects only");
}

// A path made by a script (in step 1's control phase) exists from the next
// step, under the robot's own object, with its options.
TEST(LuaApiPathsTest, CreatePathMakesAPathFromTheNextStep) {
  PathsScripts s;
  s.w.Script(s.bot, R"(
    local step = 0
    function sysCall_actuation()
      if step == 1 then
        sim.createPath({{0, 0, 0}, {3, 0, 0}, {3, 4, 0}}, {name = 'made', velocity = 0.25})
      end
    end
    function sysCall_sensing()
      step = step + 1
      local ok, h = pcall(sim.getObject, './made')
      if ok then
        print(string.format('step %d made %g', step, sim.getPathLength(h)))
      else
        print(string.format('step %d none', step))
      end
    end
  )");
  EXPECT_EQ(s.w.Run(2), "");
  EXPECT_CONTAINS(s.Log(), "step 1 none");
  EXPECT_CONTAINS(s.Log(), "step 2 made 7");
  const ObjectId made = s.w.scene().FindObject("/bot/made");
  ASSERT_FALSE(made.IsNull());
  EXPECT_EQ(s.w.scene().parent(made), s.bot);
  EXPECT_DOUBLE_EQ(s.row(made).velocity, 0.25);
}

// A path a script makes is charged to its robot for the robot's lifetime
// (simulation.script_memory_mb): a loop of long paths is refused naming
// the call, a few short ones work.
TEST(LuaApiPathsTest, PathsAScriptMakesCountAgainstItsMemoryLimit) {
  const auto run = [](const std::string& code) {
    ModuleWorld w("kinematic", 1, 0.1, int64_t{16} << 20);
    const ObjectId bot = w.Robot("bot", {});
    w.Script(bot, code);
    const std::string error = w.Run(2);
    EXPECT_LE(w.world().script_memory(0).used(), uint64_t{16} << 20);
    return std::pair(error, w.scene().FindObject("/bot/p3", {}).IsNull());
  };
  // 100,000 points a path: ~3 MiB each in C++.
  const auto [error, none] = run(R"(
    local points = {}
    for i = 1, 100000 do points[i] = {i * 0.01, 0, 0} end
    function sysCall_actuation()
      for i = 1, 20 do sim.createPath(points, {name = 'p' .. i}) end
    end
  )");
  EXPECT_CONTAINS(error,
                  "bot: script.lua:5: sim.createPath: the path would take the scripts "
                  "past 16 MiB");
  EXPECT_CONTAINS(error, "simulation.script_memory_mb");
  const auto [fine, missing] = run(R"(
    local made = false
    function sysCall_actuation()
      if made then return end
      made = true
      for i = 1, 5 do sim.createPath({{0, 0, 0}, {1, i, 0}}, {name = 'p' .. i}) end
    end
  )");
  EXPECT_EQ(fine, "");
  EXPECT_FALSE(missing);
}

}  // namespace
}  // namespace swarmsim::paths
