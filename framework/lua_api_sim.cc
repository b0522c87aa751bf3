// sim.* simulation: time, parameters, random numbers, metrics, the robot's
// identity, and print.
#include <algorithm>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/registry.h"
#include "framework/utf8.h"
#include "framework/world.h"

namespace swarmsim {
namespace {

// A metric's name: a column of metrics.csv, a label in summary.json.
constexpr size_t kMaxMetricNameBytes = 256;
// What one robot's scripts (or the scene's and the main script) may print
// in one step: a runaway print loop must not fill the disk or the memory.
constexpr size_t kMaxPrintBytesPerStep = size_t{1} << 20;

// sim.getSimulationTime() -> s, at the start of the current step.
int GetSimulationTime(lua_State* L) {
  lua_pushnumber(L, Context(L).world->time());
  return 1;
}

// sim.getTimeStep() -> s, one control step.
int GetTimeStep(lua_State* L) {
  lua_pushnumber(L, Context(L).world->settings().time_step);
  return 1;
}

// sim.random() -> uniform in [0, 1) from the robot's own stream: the same
// numbers whatever the thread count.
int Random(lua_State* L) {
  lua_pushnumber(L, Context(L).runtime->rng.Uniform());
  return 1;
}

// sim.getParam(name [, default]) -> number (an integer if integral), boolean
// or string: the robot's model parameter, else the world parameter, else the
// default.
int GetParam(lua_State* L) {
  const LuaContext& c = Context(L);
  size_t length = 0;
  const char* name = ArgString(L, 1, &length);
  const ParamValue* value = c.world->FindParameter(c.instance, {name, length});
  if (value == nullptr) {
    if (lua_gettop(L) >= 2) {
      lua_settop(L, 2);
      return 1;
    }
    throw Error("no parameter '" + std::string(name, length) +
                "': set it in the world's or the model's parameters, or give a default");
  }
  PushParamValue(L, *value);  // integral numbers as Lua integers
  return 1;
}

// sim.recordMetric(name, value): a sample of this step for this robot; the
// World collects them in robot order (World::TakeMetrics, metrics.csv).
int RecordMetric(lua_State* L) {
  LuaContext& c = Context(L);
  size_t length = 0;
  const char* name = ArgString(L, 1, &length);
  const double value = ArgNumber(L, 2);
  if (length == 0) throw Error("the metric name is empty");
  if (length > kMaxMetricNameBytes)
    throw Error("the metric name is " + std::to_string(length) + " bytes long; at most " +
                std::to_string(kMaxMetricNameBytes));
  // A NUL byte went into metrics.csv as it was (CSV readers stop there).
  if (std::memchr(name, '\0', length) != nullptr)
    throw Error("the metric name holds a NUL byte ('\\0'): a metric name is text");
  // A swarm metric of this world's `metrics:` under the same name: its rows
  // (robot empty) and the robots' would be one metric to a sweep, which
  // averaged the swarm's value in as one more robot.
  if (const std::string_view n(name, length); c.world->IsListedSwarmMetric(n))
    throw Error("'" + std::string(n) +
                "' is a swarm metric this world records (its 'metrics:' list): give the "
                "robot's metric another name");
  // What the sample holds in C++: the robot's vector of samples as it
  // grows (its capacity, charged when it doubles: the slots it really
  // holds, not just the ones used) and the name's own block when it is too
  // long for the string's inline buffer. Released, buffer and all, when the
  // World takes the samples after the phase (World::FlushRobotBuffers).
  std::vector<MetricSample>& samples = c.runtime->metrics;
  static const size_t kInlineName = std::string().capacity();
  uint64_t bytes = length > kInlineName ? length + 1 : 0;
  size_t capacity = samples.capacity();
  if (samples.size() == capacity) {
    capacity = std::max<size_t>(16, 2 * capacity);
    bytes += (capacity - samples.capacity()) * sizeof(MetricSample);
  }
  ChargeScriptData(L, bytes, "the metric sample");
  c.runtime->metric_bytes += bytes;
  samples.reserve(capacity);
  samples.push_back(
      {c.world->step_count(), c.world->time(), c.instance, std::string(name, length), value});
  return 0;
}

// sim.getRobotIndex() -> the robot's instance index (0-based); -1 in a scene script.
int GetRobotIndex(lua_State* L) {
  lua_pushinteger(L, Context(L).instance);
  return 1;
}

// sim.getRobotName() -> e.g. "footbot#12"; nil in a scene script.
int GetRobotName(lua_State* L) {
  const LuaContext& c = Context(L);
  if (c.instance < 0)
    lua_pushnil(L);
  else
    lua_pushlstring(L, c.name.data(), c.name.size());
  return 1;
}

// print(...): one line in the run's log, "[footbot#12] a\tb" (scene scripts:
// "[scene] "), written out after the phase in robot order.
int Print(lua_State* L) {
  LuaContext& c = Context(L);
  const int n = lua_gettop(L);
  // Every argument to a string first: __tostring may raise a Lua error,
  // which must not jump over `line`.
  // A string per argument, and a few slots for luaL_tolstring's own work.
  if (!lua_checkstack(L, n + LUA_MINSTACK)) throw Error("too many arguments");
  for (int i = 1; i <= n; ++i) luaL_tolstring(L, i, nullptr);  // honours __tostring
  // At most kMaxPrintBytesPerStep a step, checked before anything is copied.
  RobotRuntime& rt = *c.runtime;
  if (rt.print_step != c.world->step_count()) {
    rt.print_step = c.world->step_count();
    rt.printed_bytes = 0;
  }
  // Counted as written: a newline gets the robot's prefix, a control
  // character its escape (up to 6 bytes), so that a text of newlines cannot
  // build a line many times the cap before it is checked.
  size_t printed = static_cast<size_t>(n);  // the tabs and the newline
  for (int i = 1; i <= n; ++i) {
    size_t length = 0;
    const char* text = lua_tolstring(L, n + i, &length);
    printed += length;
    for (size_t k = 0; k < length; ++k) {
      const auto b = static_cast<unsigned char>(text[k]);
      if (b == '\n')
        printed += c.log_prefix.size();
      else if ((b < 0x20 && b != '\t') || b == 0x7f || b == 0xc2)
        printed += 5;
    }
  }
  if (rt.printed_bytes + printed > kMaxPrintBytesPerStep)
    throw Error("the scripts of " + c.name + " printed more than " +
                std::to_string(kMaxPrintBytesPerStep >> 20) +
                " MiB in this step (the most a robot may print in one step); a print in a loop?");
  // Each line of the text gets the robot's prefix (a "\n[footbot#7] ..."
  // in one robot's print read as another's line, an "\nerror: ..." as the
  // run's), and terminal controls are escaped (an ESC recoloured or cleared
  // the console). Charged as written.
  std::string line = c.log_prefix;
  const std::string newline = "\n" + c.log_prefix;
  for (int i = 1; i <= n; ++i) {
    size_t length = 0;
    const char* text = lua_tolstring(L, n + i, &length);
    if (i > 1) line += '\t';
    line += EscapeControls(std::string_view(text, length), newline);
  }
  const uint64_t bytes = line.size() + 1 + kHeldEntryBytes;
  ChargeScriptData(L, bytes, "the printed line");
  rt.printed_bytes += printed;
  rt.log_bytes += bytes;
  rt.log.Add(std::move(line));
  return 0;
}

}  // namespace

void RegisterSimApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getSimulationTime", Guarded<GetSimulationTime, "sim.getSimulationTime">},
      {"getTimeStep", Guarded<GetTimeStep, "sim.getTimeStep">},
      {"random", Guarded<Random, "sim.random">},
      {"getParam", Guarded<GetParam, "sim.getParam">},
      {"recordMetric", Guarded<RecordMetric, "sim.recordMetric">},
      {"getRobotIndex", Guarded<GetRobotIndex, "sim.getRobotIndex">},
      {"getRobotName", Guarded<GetRobotName, "sim.getRobotName">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
  lua_pushcfunction(L, (Guarded<Print, "print">));
  lua_setglobal(L, "print");
}

}  // namespace swarmsim
