// The world file's `models:` entries (swarm/loader/world_entries.cc): each
// entry's parameters, its copies with values of their own (instances:),
// --set over them, scale, and where the copies go (distribute: or
// position:), each mistake named at its file:line:column.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/proximity/proximity.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

class ControlLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_world_entries_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Write("bot.yaml",
          "model: bot\n"
          "parameters:\n"
          "  speed: {default: 0.1, unit: m/s, range: [0, 0.5], description: forward speed}\n"
          "  label: {default: plain}\n"
          "objects: {name: body, type: dummy, script: bot.lua}\n");
    Write("bot.lua", "function sysCall_init() end\n");
    Write("main.lua", "function sysCall_step() sim.handleDynamics() end\n");
    registry_.RegisterDynamics({"", "kinematic", "1", "test"}, {},
                               [] { return std::make_unique<testing::NullDynamics>(); });
    proximity::Register(&registry_, {"", "proximity", "1", "test"},
                        [] { return std::make_unique<testing::NullProximity>(); });
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  LoadedWorld Load(const std::string& world, LoadOptions options = {}) {
    Write("world.yaml", world);
    return LoadWorld(dir_ / "world.yaml", options, registry_);
  }
  std::string ErrorOf(const std::string& world, LoadOptions options = {}) {
    try {
      Load(world, options);
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  fs::path dir_;
  ModuleRegistry registry_;
};

const char kThree[] =
    "simulation: {physics: kinematic}\n"
    "models:\n"
    "  - model: bot.yaml\n"
    "    count: 3\n"
    "    distribute: {region: {min: [-5, -5], max: [5, 5]}}\n"
    "    parameters: {speed: 0.2}\n"
    "    instances:\n"
    "      - {index: 1, parameters: {speed: 0.4, label: special}}\n";

TEST_F(ControlLoaderTest, EveryEntryOfAModelKeepsItsExplicitScripts) {
  // Reading `script: {file:, explicit:}` once replaced that map by its file
  // name in the parsed model (yaml-cpp's Node assignment writes through), so
  // the second entry of the same model got a plain, self-running script.
  Write("arm.yaml",
        "model: arm\n"
        "objects:\n"
        "  {type: dummy, script: arm.lua,\n"
        "   children: [{name: x, type: dummy, script: {file: x.lua, explicit: true}}]}\n");
  Write("arm.lua",
        "function sysCall_actuation()\n"
        "  sim.recordMetric('doubled', sim.handleChildScript(sim.getObject('./x'), 21))\n"
        "end\n");
  Write("x.lua",
        "function sysCall_actuation(a) sim.recordMetric('x_ran', a or -1) return 2 * a end\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - {model: arm.yaml, position: [0, 0]}\n"
      "  - {model: arm.yaml, position: [1, 0]}\n"
      "  - {model: arm.yaml, count: 2, distribute: {region: {min: [2, 2], max: [9, 9]}}}\n");
  w.world->Step();
  int doubled = 0, x_ran = 0;
  for (const MetricSample& m : w.world->TakeMetrics()) {
    if (m.name == "doubled") doubled += m.value == 42;
    if (m.name == "x_ran") x_ran += m.value == 21;  // only when called, with its argument
  }
  EXPECT_EQ(doubled, 4);
  EXPECT_EQ(x_ran, 4);
}

TEST_F(ControlLoaderTest, PerCopyParametersOverrideTheEntrysAndSetAppliesToAll) {
  LoadedWorld w = Load(kThree);
  const World& world = *w.world;
  EXPECT_EQ(std::get<double>(*world.FindParameter(0, "speed")), 0.2);
  EXPECT_EQ(std::get<double>(*world.FindParameter(1, "speed")), 0.4);
  EXPECT_EQ(std::get<std::string>(*world.FindParameter(1, "label")), "special");
  EXPECT_EQ(std::get<double>(*world.FindParameter(2, "speed")), 0.2);
  LoadOptions set;
  set.overrides = {{"bot.speed", "0.3"}};
  LoadedWorld s = Load(kThree, set);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(std::get<double>(*s.world->FindParameter(i, "speed")), 0.3);
  EXPECT_EQ(std::get<std::string>(*s.world->FindParameter(1, "label")), "special");
  ASSERT_EQ(w.models.size(), 1u);
  EXPECT_EQ(w.models[0].instances[0].second, "label=special, speed=0.4");
}

// A default may use the parameters above it, with the values the copy ends
// with: the entry's, a copy's own, --set's.
TEST_F(ControlLoaderTest, ADefaultUsesTheParametersAboveItWithTheirFinalValues) {
  Write("bot.yaml",
        "model: bot\n"
        "parameters:\n"
        "  speed: {default: 0.1, range: [0, 0.5]}\n"
        "  turn: \"= speed * 2\"\n"
        "  label: {default: plain}\n"
        "  tag: \"= label .. '-' .. turn\"\n"
        "objects: {name: body, type: dummy, script: bot.lua}\n");
  const auto at = [](const LoadedWorld& w, int copy, const char* name) {
    const ParamValue* v = w.world->FindParameter(copy, name);
    return v == nullptr ? std::string("none") : ShowParamValue(*v);
  };
  LoadedWorld w = Load(kThree);
  EXPECT_EQ(at(w, 0, "turn"), "0.4");
  EXPECT_EQ(at(w, 1, "turn"), "0.8");  // its own speed
  EXPECT_EQ(at(w, 1, "tag"), "special-0.8");
  EXPECT_EQ(at(w, 2, "tag"), "plain-0.4");
  LoadOptions set;
  set.overrides = {{"bot.speed", "0.25"}};
  LoadedWorld s = Load(kThree, set);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(at(s, i, "turn"), "0.5") << i;
  // Given outright, a derived one is the value given.
  std::string given = kThree;
  given.replace(given.find("{speed: 0.2}"), 12, "{speed: 0.2, turn: 7}");
  EXPECT_EQ(at(Load(given), 0, "turn"), "7");
  EXPECT_EQ(at(Load(given), 1, "turn"), "7");
  // Only the ones above.
  Write("bot.yaml",
        "model: bot\n"
        "parameters:\n"
        "  turn: \"= speed * 2\"\n"
        "  speed: 0.1\n"
        "objects: {name: body, type: dummy, script: bot.lua}\n");
  EXPECT_CONTAINS(ErrorOf(kThree),
                  "bot.yaml:3:9: in expression 'speed * 2' for 'turn': "
                  "parameter 'speed' is defined below this one (at line 4)");
}

TEST_F(ControlLoaderTest, RangesAndInstanceMistakesNameFileLineAndColumn) {
  std::string bad = kThree;
  bad.replace(bad.find("speed: 0.4"), 10, "speed: 0.9");
  EXPECT_CONTAINS(ErrorOf(bad),
                  "world.yaml:8:40: parameter 'speed' of model 'bot' must be within "
                  "[0, 0.5] m/s (got 0.9)");
  bad = kThree;
  bad.replace(bad.find("index: 1"), 8, "index: 3");
  EXPECT_CONTAINS(ErrorOf(bad), "world.yaml:8:17: 'index' must be below the entry's count (3)");
  bad = kThree;
  bad.replace(bad.find("label: special"), 14, "colour: red");
  EXPECT_CONTAINS(ErrorOf(bad), "model 'bot' has no parameter 'colour'");
  LoadOptions set;
  set.overrides = {{"bot.speed", "2"}};
  EXPECT_CONTAINS(ErrorOf(kThree, set),
                  "--set bot.speed=2: parameter 'speed' of model 'bot' "
                  "must be within [0, 0.5]");
  Write("bot.yaml",
        "model: bot\nparameters:\n  speed: {default: 0.1, range: [1]}\n"
        "objects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(ErrorOf(kThree), "bot.yaml:3:32: 'range' must be [min, max]");
}

// A model file's value that the entry's parameters give (`script:
// $controller`) fails at the model file's line, which the user did not
// write: the message says which entry's parameters it used.
TEST_F(ControlLoaderTest, AModelValueFromTheEntrysParametersNamesTheEntry) {
  Write("ctl.yaml",
        "model: ctl\nparameters:\n  controller: {default: bot.lua}\n"
        "objects: {name: body, type: dummy, script: $controller}\n");
  const std::string world =
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - {model: ctl.yaml, position: [0, 0], parameters: {controller: nope.lua}}\n";
  EXPECT_CONTAINS(ErrorOf(world), "ctl.yaml:4:44: script file 'nope.lua' not found");
  EXPECT_CONTAINS(ErrorOf(world), " (with the parameters of the models entry given at " +
                                      (dir_ / "world.yaml").string() + ":3:53)");
  // Without entry parameters the model's own line says it all.
  Write("ctl.yaml", "model: ctl\nobjects: {name: body, type: dummy, script: nope.lua}\n");
  EXPECT_EQ(ErrorOf("simulation: {physics: kinematic}\nmodels: [{model: ctl.yaml, position: [0, "
                    "0]}]\n")
                .find("with the parameters"),
            std::string::npos);
}

TEST_F(ControlLoaderTest, EntryParametersAreOfTheirDeclaredType) {
  const std::string entry =
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - model: bot.yaml\n"
      "    position: [0, 0]\n"
      "    parameters: ";
  EXPECT_CONTAINS(ErrorOf(entry + "{speed: fast}\n"),
                  "world.yaml:5:25: parameter 'speed' of model 'bot' is a finite number (");
  EXPECT_CONTAINS(ErrorOf(entry + "{speed: fast}\n"), "bot.yaml:3:20), got \"fast\"");
  EXPECT_CONTAINS(ErrorOf(entry + "{sped: 0.2}\n"),
                  "world.yaml:5:18: model 'bot' has no parameter 'sped'; did you mean 'speed'?");
  // A text parameter takes whatever is given, as text.
  LoadedWorld w = Load(entry + "{label: 5}\n");
  EXPECT_EQ(std::get<std::string>(*w.world->FindParameter(0, "label")), "5");
  // A model that declares none says so.
  Write("plain.yaml", "model: plain\nobjects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(
      ErrorOf("simulation: {physics: kinematic}\n"
              "models:\n  - {model: plain.yaml, position: [0, 0], parameters: {a: 1}}\n"),
      "model 'plain' has no parameter 'a' (it declares none)");
  // A copy given twice.
  std::string twice = kThree;
  twice += "      - {index: 1, parameters: {speed: 0.1}}\n";
  EXPECT_CONTAINS(ErrorOf(twice), "world.yaml:9:17: copy 1 is given twice in 'instances'");
}

TEST_F(ControlLoaderTest, PlacementMistakesSayWhatToGive) {
  const std::string head = "simulation: {physics: kinematic}\nmodels:\n  - ";
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml}\n"),
                  "world.yaml:3:5: a models entry needs 'distribute' (with 'count') to spread "
                  "copies, or 'position: [x, y]' for a single copy");
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml, position: [0, 0], count: 2}\n"),
                  "world.yaml:3:48: 'count' other than 1 needs 'distribute'");
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml, count: 2, position: [0, 0], distribute: {}}\n"),
                  "world.yaml:3:33: 'position' places a single copy; it cannot be combined with "
                  "'distribute' (use distribute.heading_deg for a fixed heading)");
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml, count: 2, distribute: {}}\n"),
                  "distributing in the arena needs an 'arena' in the world; or give "
                  "'region: {min: [x, y], max: [x, y]}'");
  EXPECT_CONTAINS(
      ErrorOf(head +
              "{model: bot.yaml, count: 2, distribute: {region: {min: [0, 0], max: [1, 0]}}}\n"),
      "'region' needs max greater than min in x and in y");
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml, count: 2, distribute: {region: 5}}\n"),
                  "'region' must be 'arena' or {min: [x, y], max: [x, y]} (got \"5\")");
  EXPECT_CONTAINS(ErrorOf(head + "{model: bot.yaml, count: 2, distribute: {regoin: arena}}\n"),
                  "unknown key 'regoin' in 'distribute'; did you mean 'region'?");
  Write("disc.yaml",
        "model: disc\nobjects: {name: body, type: shape, shape: cylinder, radius: 0.5, "
        "height: 0.1}\n");
  EXPECT_CONTAINS(
      ErrorOf(head +
              "{model: disc.yaml, count: 1, distribute: {region: {min: [0, 0], max: [0.9, 5]}}}\n"),
      "world.yaml:3:31: the region is too small for one disc (footprint radius 0.5 m)");
}

// A large swarm left on the defaults that cost most at its size (a Lua
// state per robot, copies numbered at random) is told which setting to
// write, with where; writing either setting, either way, or a smaller
// swarm, gets no note.
TEST_F(ControlLoaderTest, LargeSwarmsOnSlowDefaultsAreToldWhatToWrite) {
  Write("plain.yaml", "model: plain\nobjects: {name: body, type: dummy}\n");
  const auto world = [](const std::string& simulation, const std::string& model,
                        const std::string& count, const std::string& order) {
    return "simulation: {physics: kinematic" + simulation +
           "}\n"
           "models:\n"
           "  - model: " +
           model + "\n    count: " + count +
           "\n"
           "    distribute: {region: {min: [-60, -60], max: [60, 60]}" +
           order + "}\n";
  };
  const auto notes = [&](const std::string& text) { return Load(text).warnings; };

  const std::vector<std::string> both = notes(world("", "bot.yaml", "10000", ""));
  ASSERT_EQ(both.size(), 2u);
  EXPECT_CONTAINS(both[0], "world.yaml:4:12: 10,000 copies of 'bot' numbered in the order");
  EXPECT_CONTAINS(both[0], "'distribute: {order: spatial}'");
  EXPECT_CONTAINS(both[1], "world.yaml: 10,000 robots run Lua scripts, a Lua state each");
  EXPECT_CONTAINS(both[1], "'simulation: {robots_per_lua_state: 64}'");

  // Each note goes when its setting is written, whichever value.
  for (const char* order : {", order: spatial", ", order: random"}) {
    const std::vector<std::string> w = notes(world("", "bot.yaml", "10000", order));
    ASSERT_EQ(w.size(), 1u) << order;
    EXPECT_CONTAINS(w[0], "robots run Lua scripts");
  }
  for (const char* rpl : {", robots_per_lua_state: 64", ", robots_per_lua_state: 1"}) {
    const std::vector<std::string> w = notes(world(rpl, "bot.yaml", "10000", ""));
    ASSERT_EQ(w.size(), 1u) << rpl;
    EXPECT_CONTAINS(w[0], "numbered in the order they were drawn");
  }
  // No scripts: no Lua note. Fewer robots: no note at all.
  const std::vector<std::string> plain = notes(world("", "plain.yaml", "10000", ""));
  ASSERT_EQ(plain.size(), 1u);
  EXPECT_CONTAINS(plain[0], "copies of 'plain'");
  EXPECT_TRUE(notes(world("", "bot.yaml", "9999", "")).empty());

  // Under box2d, one world for 10,000 robots: physics_partitions is named
  // (it was the one speed key no note mentioned), until it is written.
  registry_.RegisterDynamics({"", "box2d", "1", "test"}, {},
                             [] { return std::make_unique<testing::NullDynamics>(); });
  const auto box2d = [&](const std::string& simulation) {
    std::string text =
        world(", robots_per_lua_state: 64" + simulation, "plain.yaml", "10000", ", order: spatial");
    text.replace(text.find("kinematic"), 9, "box2d");
    return notes(text);
  };
  const std::vector<std::string> one = box2d("");
  ASSERT_EQ(one.size(), 1u);
  EXPECT_CONTAINS(one[0],
                  "world.yaml: 10,000 robots under physics: box2d in one world; with "
                  "'simulation: {physics_partitions: auto}'");
  for (const char* partitions : {", physics_partitions: auto", ", physics_partitions: 1"})
    EXPECT_TRUE(box2d(partitions).empty()) << partitions;
}

}  // namespace
}  // namespace swarmsim
