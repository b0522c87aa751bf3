// Collections, distance and collision objects (modules/collision) as a user
// writes them: world and model files run through the program, readings
// checked against hand-computed distances.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::RunProgram;

// Runs `world` (with `files`) for `steps` and returns the last value of
// each metric of metrics.csv, keyed "robot:metric".
struct WorldRun {
  int exit_code = -1;
  std::string output;
  std::map<std::string, double> last;
};

WorldRun RunWorld(const std::string& name, const std::string& world,
                  const std::map<std::string, std::string>& files = {}, int steps = 2,
                  const std::string& extra = "") {
  const fs::path dir = FreshTempDir("swarmsim_geometry", name);
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << world;
  for (const auto& [file, text] : files) std::ofstream(dir / file) << text;
  WorldRun run;
  const auto r =
      RunProgram("run " + (dir / "world.yaml").string() + " --steps " + std::to_string(steps) +
                 " --quiet --out " + (dir / "out").string() + " " + extra);
  run.exit_code = r.exit_code;
  run.output = r.output;
  for (const testing::MetricRow& row : testing::ReadMetricsCsv(dir / "out" / "metrics.csv"))
    run.last[row.robot + ":" + row.metric] = row.value;
  fs::remove_all(dir);
  return run;
}

constexpr char kTwoShapes[] =
    "simulation: {physics: kinematic, time_step: 0.1}\n"
    "objects:\n"
    "  - {name: a, type: shape, shape: box, size: [1, 1, 1], position: [0, 0, 0.5], "
    "heading_deg: HEADING}\n"
    "  - {name: b, type: shape, shape: sphere, radius: 0.5, position: [BX, 0, 0.5]}\n"
    "  - {name: gap, type: distance, between: [/a, /b]}\n"
    "  - {name: hit, type: collision, between: [/a, /b], contacts: 4}\n";

std::string TwoShapes(const std::string& heading, const std::string& bx) {
  std::string w = kTwoShapes;
  w.replace(w.find("HEADING"), 7, heading);
  w.replace(w.find("BX"), 2, bx);
  return w;
}

TEST(GeometryTest, DistanceBetweenABoxAndASphereIsExactWithItsClosestPoints) {
  const WorldRun run = RunWorld("box_sphere", TwoShapes("0", "3"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NEAR(run.last.at(":gap.distance"), 2.0, 1e-6);
  EXPECT_NEAR(run.last.at(":gap.x1"), 0.5, 1e-6);
  EXPECT_NEAR(run.last.at(":gap.x2"), 2.5, 1e-6);
  EXPECT_NEAR(run.last.at(":gap.z2"), 0.5, 1e-6);
  EXPECT_EQ(run.last.at(":hit.colliding"), 0);
}

// Turned 45 degrees, the box's edge comes 0.5 sqrt(2) towards the sphere.
TEST(GeometryTest, ATurnedBoxIsCloserByItsCorner) {
  const WorldRun run = RunWorld("turned", TwoShapes("45", "3"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NEAR(run.last.at(":gap.distance"), 3 - 0.5 * std::sqrt(2.0) - 0.5, 1e-6);
  EXPECT_NEAR(run.last.at(":gap.x1"), 0.5 * std::sqrt(2.0), 1e-6);
}

TEST(GeometryTest, OverlappingShapesCollideWithContactPointsAndDistanceZero) {
  const WorldRun run = RunWorld("overlap", TwoShapes("0", "0.9"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.last.at(":hit.colliding"), 1);
  EXPECT_GE(run.last.at(":hit.contacts"), 1);
  EXPECT_EQ(run.last.at(":gap.distance"), 0);
}

// Two robots, each with a collection of its own parts (per copy) and a
// distance object to everything else within 1 m.
constexpr char kBot[] =
    "model: bot\n"
    "objects:\n"
    "  name: body\n"
    "  type: shape\n"
    "  shape: cylinder\n"
    "  radius: 0.1\n"
    "  height: 0.2\n"
    "  script: bot.lua\n"
    "  children:\n"
    "    - {name: mast, type: shape, shape: box, size: [0.02, 0.02, 0.3], position: [0, 0, 0.2]}\n"
    "    - {name: parts, type: collection, trees: [':'], exclude_objects: [':/mast']}\n"
    "    - {name: near, type: distance, between: [':', everything_else], threshold: 1}\n"
    "    - {name: wall, type: distance, between: [':/parts', environment], record: false}\n";

constexpr char kBotLua[] =
    "function sysCall_actuation()\n"
    "  local objs = sim.getCollectionObjects(sim.getObject(':/parts'))\n"
    "  local names = {}\n"
    "  for i, h in ipairs(objs) do names[i] = sim.getObjectName(h) end\n"
    "  local d = sim.readDistance(sim.getObject(':/wall'))\n"
    "  local r, data = sim.checkDistance(sim.getObject(':'), 'environment')\n"
    "  print('parts', table.concat(names, ','), string.format('%.4f %.4f', d, data[7]))\n"
    "end\n";

std::string Robots(const std::string& x0, const std::string& x1) {
  return "simulation: {physics: kinematic, time_step: 0.1}\n"
         "obstacles:\n"
         "  - {name: wall, shape: box, size: [0.2, 4, 0.5], position: [3, 0, 0.25]}\n"
         "models:\n"
         "  - {model: bot.yaml, position: [" +
         x0 + ", 0, 0.1]}\n  - {model: bot.yaml, position: [" + x1 + ", 0, 0.1]}\n";
}

TEST(GeometryTest, ModelCollectionsAndDistanceObjectsArePerCopy) {
  const WorldRun run =
      RunWorld("robots", Robots("0", "0.5"), {{"bot.yaml", kBot}, {"bot.lua", kBotLua}});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // Each copy's collection holds its own body (the mast excluded; collections
  // hold no collections).
  EXPECT_NE(run.output.find("[bot#0] parts\tbot#0,near,wall\t"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("[bot#1] parts\tbot#1,near,wall\t"), std::string::npos);
  // bot#1's body faces the wall at x = 2.9: 2.9 - 0.5 - 0.1 = 2.3; the
  // file's object and the script's check agree.
  EXPECT_NE(run.output.find("[bot#1] parts\tbot#1,near,wall\t2.3000 2.3000"), std::string::npos)
      << run.output;
  // Bodies 0.5 apart: 0.3 between the cylinders' surfaces (the masts are
  // thinner than the bodies).
  EXPECT_NEAR(run.last.at("bot#0:near.distance"), 0.3, 1e-6);
  EXPECT_NEAR(run.last.at("bot#1:near.distance"), 0.3, 1e-6);
  EXPECT_EQ(run.last.count("bot#0:wall.distance"), 0u);  // record: false
}

TEST(GeometryTest, NothingWithinTheThresholdReadsInfinity) {
  const WorldRun run =
      RunWorld("far", Robots("-3", "0"), {{"bot.yaml", kBot}, {"bot.lua", kBotLua}});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(std::isinf(run.last.at("bot#0:near.distance")));
  EXPECT_FALSE(run.last.count("bot#0:near.x1"));
}

TEST(GeometryTest, ScriptCollectionsAndChecks) {
  const std::string lua =
      "function sysCall_init()\n"
      "  local c = sim.createCollection()\n"
      "  sim.addItemToCollection(c, sim.handle_tree, sim.getObject(':'))\n"
      "  sim.addItemToCollection(c, sim.handle_single, sim.getObject(':/mast'), 1)\n"
      "  print('n', #sim.getCollectionObjects(c))\n"
      "  print('hit', sim.checkCollision(c, sim.getObject(':/mast')),\n"
      "        sim.checkCollision(c, 'environment'))\n"
      "  local ok, err = pcall(sim.addItemToCollection, sim.getObject(':/parts'), "
      "sim.handle_all, 0)\n"
      "  print('fixed', ok, err)\n"
      "end\n";
  const WorldRun run =
      RunWorld("script", Robots("0", "0.5"), {{"bot.yaml", kBot}, {"bot.lua", lua}});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("[bot#0] n\t3"), std::string::npos) << run.output;
  // The mast sinks 5 cm into the body; the wall is 2.8 m away.
  EXPECT_NE(run.output.find("[bot#0] hit\t1\t0"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("cannot change; make one with sim.createCollection"), std::string::npos)
      << run.output;
}

TEST(GeometryTest, BadEntitiesAreErrorsNamingWhere) {
  const auto fails = [](const std::string& name, const std::string& object,
                        const std::string& expected) {
    const WorldRun run = RunWorld(name,
                                  "simulation: {physics: kinematic, time_step: 0.1}\n"
                                  "objects:\n"
                                  "  - {name: a, type: shape, shape: box, size: [1, 1, 1]}\n"
                                  "  - " +
                                      object + "\n");
    EXPECT_EQ(run.exit_code, 2) << name;
    EXPECT_NE(run.output.find(expected), std::string::npos) << name << ": " << run.output;
  };
  fails("one", "{name: d, type: distance, between: [/a]}",
        "world.yaml:4:40: 'between' takes two entities");
  fails("first_env", "{name: d, type: distance, between: [environment, /a]}",
        "the first entity must be an object or a collection");
  fails("not_path", "{name: d, type: distance, between: [/a, wall]}",
        "'wall' is neither an object path");
  // Paths are checked once the world is built: at their file:line:col, exit 2.
  fails("missing", "{name: d, type: distance, between: [/a, /b]}",
        "world.yaml:4:40: distance object /d: '/b' matches no object");
  fails("same", "{name: d, type: distance, between: [/a, /a]}",
        "world.yaml:4:40: distance object /d: '/a' and '/a' are the same objects");
  fails("threshold", "{name: d, type: distance, between: [/a, environment], threshold: -1}",
        "positive number");
  fails("collection",
        "{name: c, type: collection, trees: [/nope]}\n"
        "  - {name: d, type: distance, between: [/a, /c]}",
        "world.yaml:4:40: collection /c: item '/nope' matches no object");
  // Even when nothing uses the collection.
  fails("unused_collection", "{name: c, type: collection, objects: [/a, /missing]}",
        "world.yaml:4:42: collection /c: item '/missing' matches no object");
}

}  // namespace
}  // namespace swarmsim

namespace swarmsim {
namespace {

// A cone sensor's `detectable:` set: only the far box, though the near one
// is in the cone.
TEST(GeometryTest, AConeSensorDetectsOnlyItsDetectableSet) {
  const auto run = [](const std::string& detectable) {
    return RunWorld(
        "detectable" + std::to_string(detectable.size()),
        "simulation: {physics: kinematic, time_step: 0.1}\n"
        "obstacles:\n"
        "  - {name: near, shape: box, size: [0.2, 0.2, 0.2], position: [1, 0, 0.1]}\n"
        "  - {name: far, shape: box, size: [0.2, 0.2, 0.2], position: [2, 0.2, 0.1]}\n"
        "models:\n  - {model: probe.yaml, position: [0, 0, 0.1]}\n",
        {{"probe.yaml",
          "model: probe\nobjects:\n  name: body\n  type: dummy\n  children:\n"
          "    - {name: eye, type: proximity_sensor, volume: cone, angle_deg: 45, range: 5,\n"
          "       orientation_deg: [0, 90, 0], script: eye.lua" +
              detectable + "}\n"},
         {"eye.lua",
          "function sysCall_actuation()\n"
          "  local r, d, p, h = sim.readProximitySensor(sim.getObject('.'))\n"
          "  print('seen', r, string.format('%.6f', d), sim.getObjectName(h))\n"
          "end\n"}});
  };
  const WorldRun all = run("");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_NE(all.output.find("seen\t1\t0.900000\tnear"), std::string::npos) << all.output;
  const WorldRun far = run(", detectable: /far");
  ASSERT_EQ(far.exit_code, 0) << far.output;
  // The far box's nearest face point to the sensor: (1.9, 0.1, 0).
  EXPECT_NE(far.output.find("seen\t1\t" + std::string("1.902630") + "\tfar"), std::string::npos)
      << far.output;
  const WorldRun ray = RunWorld("detectable_ray",
                                "simulation: {physics: kinematic, time_step: 0.1}\n"
                                "models:\n  - {model: probe.yaml}\n",
                                {{"probe.yaml",
                                  "model: probe\nobjects:\n  name: body\n  type: dummy\n"
                                  "  children:\n    - {name: eye, type: proximity_sensor, "
                                  "detectable: /far}\n"}});
  EXPECT_NE(ray.exit_code, 0);
  EXPECT_NE(ray.output.find("'detectable' applies to volume and randomized_ray sensors only"),
            std::string::npos)
      << ray.output;
}

}  // namespace
}  // namespace swarmsim

namespace swarmsim {
namespace {

// A box's nearest point on its bottom edge: the bottom face (facing the
// sensor, 14 degrees off) is the normal there, so a 45-degree reflectance
// cut-off keeps the detection.
TEST(GeometryTest, TheCutOffTakesTheFaceOfAnEdgeThatFacesTheSensor) {
  const WorldRun run = RunWorld(
      "cutoff_edge",
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "obstacles:\n"
      "  - {name: box, shape: box, size: [0.2, 0.2, 0.2], position: [0.2, 0, 0.5]}\n"
      "models:\n  - {model: probe.yaml, position: [0, 0, 0]}\n",
      {{"probe.yaml",
        "model: probe\nobjects:\n  name: body\n  type: dummy\n  children:\n"
        "    - {name: eye, type: proximity_sensor, volume: cone, angle_deg: 30, range: 1,\n"
        "       max_detection_angle_deg: 45, script: eye.lua}\n"},
       {"eye.lua",
        "function sysCall_actuation()\n"
        "  local r, d, p, h, n = sim.readProximitySensor(sim.getObject('.'))\n"
        "  print('seen', r, string.format('%.5f %g %g %g', d or -1, n and n[1] or 9,\n"
        "        n and n[2] or 9, n and n[3] or 9))\n"
        "end\n"}});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("seen\t1\t0.41231 0 0 -1"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace swarmsim
