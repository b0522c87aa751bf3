// Plugin sensors (framework/plugin_sensors.cc): the objects of type
// plugin_sensor, sensed in the sense phase by the function their type's
// plugin registered, each robot's with its own context; readings of the
// type's size, read from C++ and from Lua (sim.readPluginSensor), and a
// failing sensor named in the error.
#include "framework/plugin_sensors.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

using testing::ErrorOf;

// Writes {robot, sensor handle, step}; fails for robots listed in
// *user_data's `fail` (a message) or `overflow` (too many values).
struct Behaviour {
  std::vector<int> fail, overflow;
  int calls = 0;
};

bool Has(const std::vector<int>& v, int x) {
  for (int y : v)
    if (y == x) return true;
  return false;
}

int Sense(const SwarmsimCallContext* context, int64_t sensor, double* values, int max_values,
          char* error, size_t error_size, void* user_data) {
  const auto* behaviour = static_cast<const Behaviour*>(user_data);
  if (Has(behaviour->fail, context->robot)) {
    std::snprintf(error, error_size, "robot %d has no light", context->robot);
    return -1;
  }
  if (Has(behaviour->overflow, context->robot)) return max_values + 1;
  values[0] = context->robot;
  values[1] = static_cast<double>(sensor);
  return 2;
}

class SensorWorld {
 public:
  explicit SensorWorld(Behaviour* behaviour, int threads = 1) : registry_(testing::NullRegistry()) {
    registry_.RegisterPluginSensor({"", "test", "1", "a test sensor"},
                                   {"probe", "robot and handle", Sense, behaviour, 4});
    WorldSettings settings;
    settings.physics = "null";
    settings.threads = threads;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }
  // Robot `name` with a probe `eye` (of sensor type `type`); returns the probe.
  ObjectId AddRobot(const std::string& name, const std::string& code = "",
                    const std::string& type = "probe") {
    const ObjectId root = scene().AddDummy(name, {}, {});
    const PluginSensorRow row{type};
    const ObjectId eye = scene().AddObject(ObjectType::kPluginSensor, "eye", root, {}, &row);
    scene().MakeModelInstance(root, "bot", name);
    if (!code.empty())
      scene().AttachScript(
          root, std::make_shared<const ScriptSource>(ScriptSource{"scripts/robot.lua", code}));
    return eye;
  }
  std::vector<double> Reading(ObjectId id) {
    std::span<const double> values;
    if (!PluginSensorReading(*world_, id, &values)) return {};
    return {values.begin(), values.end()};
  }
  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

TEST(PluginSensorsTest, EachSensorIsSensedWithItsRobotsContext) {
  Behaviour behaviour;
  SensorWorld w(&behaviour);
  const ObjectId eye0 = w.AddRobot("bot#0");
  const ObjectId eye1 = w.AddRobot("bot#1");
  const PluginSensorRow row{"probe"};
  const ObjectId mast = w.scene().AddObject(ObjectType::kPluginSensor, "mast", {}, {}, &row);
  EXPECT_TRUE(w.Reading(eye0).empty());  // nothing before the first sense phase
  w.world().Step();
  EXPECT_EQ(w.Reading(eye0), (std::vector<double>{0, static_cast<double>(eye0.ToInteger())}));
  EXPECT_EQ(w.Reading(eye1), (std::vector<double>{1, static_cast<double>(eye1.ToInteger())}));
  EXPECT_EQ(w.Reading(mast), (std::vector<double>{-1, static_cast<double>(mast.ToInteger())}));
  // A sensor added since the last sense phase has no reading until the next.
  const ObjectId late = w.scene().AddObject(ObjectType::kPluginSensor, "late", {}, {}, &row);
  EXPECT_TRUE(w.Reading(late).empty());
  w.world().Step();
  EXPECT_EQ(w.Reading(late), (std::vector<double>{-1, static_cast<double>(late.ToInteger())}));
  EXPECT_EQ(ErrorOf([&] { w.Reading(w.scene().FindObject("/bot#0")); }),
            "object /bot#0 is not a plugin sensor");
}

TEST(PluginSensorsTest, ScriptsReadTheLastReadingOrNil) {
  Behaviour behaviour;
  SensorWorld w(&behaviour);
  w.AddRobot("bot#0", R"(
    function sysCall_sensing()
      local r = sim.readPluginSensor(sim.getObject(':/eye'))
      print(r and #r, r and r[1])
    end
  )");
  w.world().Step();
  EXPECT_EQ(w.log, std::vector<std::string>{"[bot#0] 2\t0.0"});
}

// The lowest robot's failure is reported, whatever the thread count.
TEST(PluginSensorsTest, AFailingSensorIsNamedWithItsMessage) {
  for (int threads : {1, 2, 4}) {
    Behaviour behaviour;
    behaviour.fail = {5, 3, 9};
    SensorWorld w(&behaviour, threads);
    for (int r = 0; r < 12; ++r) w.AddRobot("bot#" + std::to_string(r));
    EXPECT_EQ(ErrorOf([&] { w.world().Step(); }),
              "plugin sensor 'probe' (/bot#3/eye): robot 3 has no light")
        << threads << " threads";
  }
  Behaviour overflow;
  overflow.overflow = {0};
  SensorWorld w(&overflow);
  w.AddRobot("bot#0");
  EXPECT_EQ(ErrorOf([&] { w.world().Step(); }),
            "plugin sensor 'probe' (/bot#0/eye): returned 5 values, at most 4 fit");
}

TEST(PluginSensorsTest, ASensorOfAnUnregisteredTypeIsAnError) {
  Behaviour behaviour;
  SensorWorld w(&behaviour);
  w.AddRobot("bot#0", "", "lidar");
  EXPECT_EQ(ErrorOf([&] { w.world().Step(); }),
            "object /bot#0/eye is a plugin sensor of type 'lidar', which no loaded plugin "
            "registers");
}

TEST(PluginSensorsTest, TypesNeedANameAFunctionAndRoomAndComeOnce) {
  ModuleRegistry registry;
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterPluginSensor({}, {"", "", Sense, nullptr, 4});
            }),
            "a plugin sensor type needs a name and a sense function");
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterPluginSensor({}, {"x", "", nullptr, nullptr, 4});
            }),
            "a plugin sensor type needs a name and a sense function");
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterPluginSensor({}, {"x", "", Sense, nullptr, 0});
            }),
            "plugin sensor type 'x' holds no values");
  registry.RegisterPluginSensor({}, {"x", "", Sense, nullptr, 4});
  registry.RegisterPluginSensor({}, {"y", "", Sense, nullptr, 4});
  EXPECT_EQ(ErrorOf([&] {
              registry.RegisterPluginSensor({}, {"x", "", Sense, nullptr, 4});
            }),
            "plugin sensor type 'x' is registered twice");
  // One module senses every type: sense phase, after proximity (order 200).
  ASSERT_EQ(registry.module_descriptors().size(), 1u);
  const ModuleDescriptor* module = registry.FindModule("plugin_sensors");
  ASSERT_NE(module, nullptr);
  EXPECT_EQ(module->phases, PhaseBit(Phase::kSense));
  EXPECT_EQ(module->order, 200);
  EXPECT_TRUE(module->every_world);
}

}  // namespace
}  // namespace swarmsim
