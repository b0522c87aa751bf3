// modules/proximity/lua_api_proximity.cc: sim.readProximitySensor and
// sim.readProximitySensors, on readings set by the test (the null backend
// of tests/framework/fakes.h leaves them alone).
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "framework/world.h"
#include "modules/proximity/proximity_sensor.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

std::shared_ptr<const ScriptSource> Source(std::string path, std::string code) {
  return std::make_shared<const ScriptSource>(ScriptSource{std::move(path), std::move(code)});
}

// A world with null modules (the proximity module's type and Lua area, a
// backend that senses nothing) whose script output lands in `log`.
class ScriptWorld {
 public:
  ScriptWorld() : registry_(testing::NullRegistry()) {
    WorldSettings settings;
    settings.physics = "null";
    settings.time_step = 0.1;
    settings.threads = 1;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }

  // A robot: a root dummy named like the instance carrying a `body` shape
  // with `code` attached. Returns the body.
  ObjectId AddRobot(const std::string& name, const std::string& code,
                    const std::string& path = "scripts/robot.lua") {
    const ObjectId root = scene().AddDummy(name, {}, {});
    const ObjectId body = scene().AddShape("body", root, {}, {});
    scene().MakeModelInstance(root, "bot", name);
    scene().AttachScript(body, Source(path, code));
    return body;
  }

  std::vector<std::string> log;

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
};

using testing::ErrorOf;

TEST(ProximityLuaApiTest, ReadProximitySensorReturnsTheReading) {
  ScriptWorld w;
  const ObjectId body = w.AddRobot("bot#0", R"(
    function sysCall_sensing()
      for i = 0, 1 do
        local h = sim.getObject('./prox[' .. i .. ']')
        print(select('#', sim.readProximitySensor(h)))
        local detected, distance, point, object, normal = sim.readProximitySensor(h)
        if detected == 1 then
          print(detected, distance, point[1], point[2], point[3], sim.getObjectName(object),
                normal[1], normal[2], normal[3])
        else
          print(detected)
        end
      end
    end
  )");
  const ObjectId wall = w.scene().AddShape("wall", {}, {}, {});
  const ObjectId p0 = proximity::AddSensor(&w.scene(), "prox", body, {}, {});
  proximity::AddSensor(&w.scene(), "prox", body, {}, {});
  ProximitySensorData& reading = proximity::MutableSensor(&w.scene(), p0);
  reading.detected = true;
  reading.distance = 0.0625;
  reading.detected_object = wall;
  reading.normal = {0, 0, -1};
  w.world().Start();
  w.world().Step();  // the null proximity module leaves the readings alone
  // CoppeliaSim's order: result, distance, point, object, normal.
  const std::vector<std::string> expected = {
      "[bot#0] 5", "[bot#0] 1\t0.0625\t0.0\t0.0\t0.0625\twall\t0.0\t0.0\t-1.0", "[bot#0] 1",
      "[bot#0] 0"};
  EXPECT_EQ(w.log, expected);
}

// The batched read gives what the per-sensor read gives, in place in the
// caller's table (same table every call, its other entries untouched), and
// follows the readings as they change.
TEST(ProximityLuaApiTest, ReadProximitySensorsReadsAllIntoOneTable) {
  ScriptWorld w;
  const ObjectId body = w.AddRobot("bot#0", R"(
    local handles, out = {}, {extra = 'kept'}
    function sysCall_init()
      for i = 0, 2 do handles[i + 1] = sim.getObject('./prox[' .. i .. ']') end
    end
    function sysCall_sensing()
      local count, same = sim.readProximitySensors(handles, out)
      local line = {count, tostring(same == out), out.extra}
      for i = 1, #handles do
        local detected, distance = sim.readProximitySensor(handles[i])
        line[#line + 1] = out[i] .. '/' .. (detected == 1 and distance or -1)
      end
      local fresh_count, fresh = sim.readProximitySensors(handles)
      line[#line + 1] = fresh_count .. ':' .. table.concat(fresh, ',')
      print(table.concat(line, ' '))
    end
  )");
  std::vector<ObjectId> prox;
  for (int i = 0; i < 3; ++i)
    prox.push_back(proximity::AddSensor(&w.scene(), "prox", body, {}, {}));
  const auto see = [&](int i, bool detected, double distance) {
    ProximitySensorData& reading = proximity::MutableSensor(&w.scene(), prox[i]);
    reading.detected = detected;
    reading.distance = distance;
  };
  see(0, true, 0.0625);
  see(2, true, 0.03125);
  w.world().Start();
  w.world().Step();  // the null proximity module leaves the readings alone
  see(0, false, 0);
  see(1, true, 0.5);
  w.world().Step();
  const std::vector<std::string> expected = {
      "[bot#0] 2 true kept 0.0625/0.0625 -1/-1 0.03125/0.03125 2:0.0625,-1,0.03125",
      "[bot#0] 2 true kept -1/-1 0.5/0.5 0.03125/0.03125 2:-1,0.5,0.03125"};
  EXPECT_EQ(w.log, expected);
}

TEST(ProximityLuaApiTest, ReadProximitySensorsNamesABadHandle) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"sim.readProximitySensors({sim.getObject('./prox'), 123456})",
       "sim.readProximitySensors: handles[2]: proximity sensor handle 123456 does not exist"},
      // After sensors, an object of another type (read by the sensors' type).
      {"sim.readProximitySensors({sim.getObject('./prox'), sim.getObject('./prox'), "
       "sim.getObject('.')})",
       "sim.readProximitySensors: handles[3]: object 'body' is a shape, not a proximity_sensor"},
      {"sim.readProximitySensors({sim.getObject('./prox'), 'x'})",
       "sim.readProximitySensors: handles[2] is not an object handle (got string)"},
      {"sim.readProximitySensors(3)",
       "sim.readProximitySensors: bad argument #1 (table expected, got number)"},
      {"sim.readProximitySensors({}, 3)",
       "sim.readProximitySensors: bad argument #2 (table expected, got number)"},
  };
  for (const auto& [call, message] : cases) {
    ScriptWorld w;
    const ObjectId body = w.AddRobot(
        "bot#0", "function sysCall_sensing()\n\n  local r = " + call + "\nend", "scripts/call.lua");
    proximity::AddSensor(&w.scene(), "prox", body, {}, {});
    w.world().Start();
    EXPECT_CONTAINS(ErrorOf([&] { w.world().Step(); }), "bot#0: scripts/call.lua:3: " + message);
  }
}

}  // namespace
}  // namespace swarmsim
