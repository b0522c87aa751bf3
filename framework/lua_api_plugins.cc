// Plugin script commands (framework/plugin_api.h) as sim.* functions: the
// arguments and results cross as SwarmsimValue, never as Lua values; and
// sim.readPluginSensor, the Lua area of the plugin_sensor type
// (framework/types/plugin_sensor_type.cc).
#include <string>
#include <vector>

#include "framework/lua_api.h"
#include "framework/plugin_sensors.h"
#include "framework/plugin_world_api.h"
#include "framework/registry.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

constexpr int kMaxResults = 16;

struct PluginResults {
  const SwarmsimValue* values;
  int count;
};

// Pushes a command's results (argument 1: its PluginResults).
int PushResults(lua_State* L) {
  const auto& results = *static_cast<const PluginResults*>(lua_touserdata(L, 1));
  for (int i = 0; i < results.count; ++i) {
    const SwarmsimValue& r = results.values[i];
    switch (r.type) {
      // Whole numbers as Lua integers (3, not 3.0), as getParam gives them.
      case kSwarmsimNumber: PushValueNumber(L, r.number); break;
      case kSwarmsimString: lua_pushlstring(L, r.text != nullptr ? r.text : "", r.size); break;
      case kSwarmsimNumbers: PushNumberArray(L, r.numbers, static_cast<int>(r.size)); break;
      default: lua_pushnil(L); break;
    }
  }
  return results.count;
}

// The closure every plugin command becomes; upvalue 1: its ScriptCommand.
int CallPluginCommand(lua_State* L) {
  const auto* command = static_cast<const ScriptCommand*>(lua_touserdata(L, lua_upvalueindex(1)));
  LuaContext& c = Context(L);
  const int n = lua_gettop(L);
  std::vector<SwarmsimValue> args(n);
  std::vector<std::vector<double>> arrays;
  arrays.reserve(n);
  // The arrays' copies, charged to the robot: a table's length may be a
  // border far past its entries ({[1] = 1, [2^40] = 1}).
  CallCharge charge(L, "the copy of an array argument");
  uint64_t copied = 0;
  for (int i = 1; i <= n; ++i) {
    SwarmsimValue& v = args[i - 1];
    v = {};
    switch (lua_type(L, i)) {
      case LUA_TNIL: break;
      case LUA_TNUMBER: v.type = kSwarmsimNumber, v.number = lua_tonumber(L, i); break;
      case LUA_TBOOLEAN: v.type = kSwarmsimNumber, v.number = lua_toboolean(L, i); break;
      case LUA_TSTRING: v.type = kSwarmsimString, v.text = lua_tolstring(L, i, &v.size); break;
      case LUA_TTABLE: {
        // Element by element, never sized from #t (a border may lie far
        // past the entries): a missing element ends it at once.
        const uint64_t length = lua_rawlen(L, i);
        std::vector<double>& a = arrays.emplace_back();
        for (uint64_t k = 0; k < length; ++k) {
          lua_rawgeti(L, i, static_cast<lua_Integer>(k + 1));
          if (!lua_isnumber(L, -1))
            RaiseError(L, "sim." + command->name + ": argument " + std::to_string(i) +
                              " must be an array of numbers");
          copied += sizeof(double);
          charge.Hold(copied);
          a.push_back(lua_tonumber(L, -1));
          lua_pop(L, 1);
        }
        v.type = kSwarmsimNumbers, v.numbers = a.data(), v.size = a.size();
        break;
      }
      default:
        RaiseError(L, "sim." + command->name + ": argument " + std::to_string(i) +
                          " must be a number, string or array of numbers, got " +
                          luaL_typename(L, i));
    }
  }
  const SwarmsimCallContext context{c.instance,
                                    c.script_object.IsNull() ? 0 : c.script_object.ToInteger(),
                                    c.world, PluginWorldApi()};
  SwarmsimValue results[kMaxResults] = {};
  char error[512] = {0};
  const int count = command->function(&context, args.data(), n, results, kMaxResults, error,
                                      sizeof error, command->user_data);
  if (count < 0 || count > kMaxResults)
    RaiseError(L, "sim." + command->name + ": " + (error[0] ? error : "the plugin command failed"));
  if (!lua_checkstack(L, count + 2))
    RaiseError(L, "sim." + command->name + ": its results do not fit on Lua's stack");
  // In protected mode: the arguments' copies are still alive.
  PluginResults pushed{results, count};
  lua_pushcfunction(L, PushResults);
  lua_pushlightuserdata(L, &pushed);
  if (lua_pcall(L, 1, count, 0) != LUA_OK) throw LuaErrorOnStack{};
  return count;
}

// sim.readPluginSensor(h) -> the sensor's last reading, an array of
// numbers, or nil before its first sense phase. Readings are written in the
// sense phase only, so any robot may read any sensor.
int ReadPluginSensor(lua_State* L) {
  const LuaContext& c = Context(L);
  if (c.world == nullptr) RaiseError(L, "sim.readPluginSensor: no world");
  std::span<const double> values;
  if (!PluginSensorReading(*c.world, CheckObject(L, 1), &values)) {
    lua_pushnil(L);
    return 1;
  }
  PushNumberArray(L, values.data(), static_cast<int>(values.size()));
  return 1;
}

}  // namespace

void RegisterPluginSensorApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readPluginSensor", Guarded<ReadPluginSensor, "sim.readPluginSensor">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

bool PushPluginCommand(lua_State* L, std::string_view name) {
  const LuaContext& c = Context(L);
  if (c.world == nullptr) return false;
  const ScriptCommand* command = c.world->registry().FindScriptCommand(name);
  if (command == nullptr) return false;
  lua_pushlightuserdata(L, const_cast<ScriptCommand*>(command));
  lua_pushcclosure(L, (Guarded<CallPluginCommand, "">), 1);
  return true;
}

}  // namespace swarmsim
