// Hints for the sysCall_* names a script defines (script_hints.h).
#include "framework/script_hints.h"

#include <algorithm>
#include <cctype>
#include <climits>
#include <iterator>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/suggest.h"

namespace swarmsim::lua_host {
namespace {

// The callbacks each kind of script gets called: child scripts (a robot's,
// the scene's), explicit child scripts (through sim.handleChildScript) and
// the world's main script.
constexpr Callback kChildCallbacks[] = {kInit, kSensing, kActuation, kCleanup, kThread};
constexpr Callback kExplicitCallbacks[] = {kInit, kSensing, kActuation, kCleanup};
constexpr Callback kMainCallbacks[] = {kInit, kStep, kCleanup};

// CoppeliaSim callbacks a ported script may define, which swarmsim never
// calls, and what to do instead.
struct PortedCallback {
  const char* name;
  const char* hint;
};
constexpr PortedCallback kCoppeliaSimCallbacks[] = {
    {"sysCall_beforeSimulation", "put its code in sysCall_init"},
    {"sysCall_afterSimulation", "put its code in sysCall_cleanup"},
    {"sysCall_nonSimulation", "scripts run only while simulating"},
    {"sysCall_beforeMainScript", "a world's own main script is simulation.main_script"},
    {"sysCall_suspend", "a run is never paused"},
    {"sysCall_suspended", "a run is never paused"},
    {"sysCall_resume", "a run is never paused"},
    {"sysCall_realTimeIdle", "a run is never paused"},
    {"sysCall_beforeInstanceSwitch", "there is one scene"},
    {"sysCall_afterInstanceSwitch", "there is one scene"},
    {"sysCall_beforeSave", "scenes are never saved"},
    {"sysCall_afterSave", "scenes are never saved"},
    {"sysCall_afterLoad", "put its code in sysCall_init"},
    {"sysCall_beforeCopy", "scripts are not told of copies"},
    {"sysCall_afterCopy", "scripts are not told of copies"},
    {"sysCall_afterCreate", "put its code in sysCall_init"},
    {"sysCall_beforeDelete", "scripts are not told of deletions"},
    {"sysCall_afterDelete", "scripts are not told of deletions"},
    {"sysCall_dynCallback", "the physics engines call no scripts"},
    {"sysCall_jointCallback",
     "the physics engines call no scripts; drive joints with sim.setJointTargetVelocity/Position"},
    {"sysCall_contactCallback", "the physics engines call no scripts"},
    {"sysCall_vision", "there are no vision sensors"},
    {"sysCall_trigger", "read proximity sensors with sim.readProximitySensor"},
    {"sysCall_userConfig", "runs are headless"},
    {"sysCall_selChange", "runs are headless"},
    {"sysCall_msg", "read messages with sim.receiveMessage"},
    {"sysCall_event", "runs are headless"},
    {"sysCall_addOnScriptSuspend", "there are no add-ons"},
    {"sysCall_addOnScriptResume", "there are no add-ons"},
    {"sysCall_moduleEntry", "there are no add-ons"},
};

// Why swarmsim never calls the script's global `name` (a sysCall_* it does
// not call for this kind of script), as the end of a warning.
std::string UncalledHint(std::string_view name, std::span<const Callback> called, bool is_main,
                         bool explicit_handling) {
  for (const PortedCallback& ported : kCoppeliaSimCallbacks)
    if (name == ported.name) return std::string("it is CoppeliaSim's; ") + ported.hint;
  if (name == kCallbackNames[kStep])
    return "only the world's main script, simulation.main_script, has a sysCall_step";
  if (is_main && (name == kCallbackNames[kSensing] || name == kCallbackNames[kActuation] ||
                  name == kCallbackNames[kThread]))
    return "the main script runs sysCall_init, sysCall_step and sysCall_cleanup; it runs the "
           "robots' callbacks with sim.handleChildScripts";
  if (explicit_handling && name == kCallbackNames[kThread])
    return "an explicit script runs only through sim.handleChildScript, which calls its "
           "sysCall_sensing or sysCall_actuation";
  std::vector<std::string> names;
  for (Callback callback : called) names.emplace_back(kCallbackNames[callback]);
  if (const std::string* nearest = NearestName(name, names))
    return "did you mean " + *nearest + "?";
  std::string list = "it calls ";
  for (size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return list;
}

}  // namespace

void CheckSysCallNames(ScriptState& state, const Script& script) {
  lua_State* L = state.L;
  const bool is_main = state.context.is_main;
  const std::span<const Callback> called = is_main ? std::span<const Callback>(kMainCallbacks)
                                           : script.explicit_handling
                                               ? std::span<const Callback>(kExplicitCallbacks)
                                               : std::span<const Callback>(kChildCallbacks);
  std::vector<UncalledSysCall> uncalled;
  const std::string& path = script.source->path;
  lua_rawgeti(L, LUA_REGISTRYINDEX, script.env_ref);
  lua_pushnil(L);
  while (lua_next(L, -2) != 0) {
    size_t length = 0;
    const char* key = lua_type(L, -2) == LUA_TSTRING ? lua_tolstring(L, -2, &length) : nullptr;
    constexpr std::string_view kPrefix = "syscall_";
    if (key == nullptr || length < kPrefix.size() ||
        !std::equal(kPrefix.begin(), kPrefix.end(), key, [](char a, char b) {
          return a == std::tolower(static_cast<unsigned char>(b));
        })) {
      lua_pop(L, 1);
      continue;
    }
    const std::string_view name(key, length);
    const bool is_called = std::any_of(called.begin(), called.end(), [&](Callback callback) {
      return name == kCallbackNames[callback];
    });
    if (is_called) {
      if (lua_type(L, -1) != LUA_TFUNCTION) {
        const std::string message = path + ": " + std::string(name) + " must be a function (got " +
                                    luaL_typename(L, -1) + ")";
        ThrowScriptError(state, script, message, "loading the script");
      }
    } else {
      UncalledSysCall& u = uncalled.emplace_back(UncalledSysCall{path, std::string(name), 0, {}});
      if (lua_isfunction(L, -1)) {
        lua_Debug ar;
        lua_pushvalue(L, -1);
        lua_getinfo(L, ">S", &ar);  // pops the copy
        if (ar.source[0] == '@' && path == ar.source + 1 && ar.linedefined > 0)
          u.line = ar.linedefined;
      }
    }
    lua_pop(L, 1);
  }
  lua_settop(L, 0);
  std::sort(uncalled.begin(), uncalled.end(),
            [](const UncalledSysCall& a, const UncalledSysCall& b) {
              const int line_a = a.line > 0 ? a.line : INT_MAX;
              const int line_b = b.line > 0 ? b.line : INT_MAX;
              return line_a != line_b ? line_a < line_b : a.name < b.name;
            });
  for (UncalledSysCall& u : uncalled) {
    u.warning = "warning: " + path;
    if (u.line > 0) u.warning.append(":").append(std::to_string(u.line)).append(":");
    u.warning += " defines " + u.name + ", which swarmsim never calls (" +
                 UncalledHint(u.name, called, is_main, script.explicit_handling) + ")";
    state.warnings.push_back(std::move(u));
  }
}

std::string MisspeltStepHint(const std::vector<UncalledSysCall>& uncalled) {
  std::vector<std::string> names;
  for (const UncalledSysCall& u : uncalled) {
    const bool known =
        std::any_of(std::begin(kCallbackNames), std::end(kCallbackNames),
                    [&](const char* n) { return u.name == n; }) ||
        std::any_of(std::begin(kCoppeliaSimCallbacks), std::end(kCoppeliaSimCallbacks),
                    [&](const PortedCallback& p) { return u.name == p.name; });
    names.push_back(known ? std::string() : u.name);  // "" is never near
  }
  const std::string* nearest = NearestName(kCallbackNames[kStep], names);
  if (nearest == nullptr) return "";
  const UncalledSysCall& u = uncalled[static_cast<size_t>(nearest - names.data())];
  std::string where = u.file;
  if (u.line > 0) where.append(":").append(std::to_string(u.line));
  return "; " + where + " defines " + u.name + ": did you mean " + kCallbackNames[kStep] + "?";
}

}  // namespace swarmsim::lua_host
