// The errors of the Lua host: their text, and what a failing script does
// under on_script_error.
#include "framework/script_state.h"

#include <string>
#include <string_view>
#include <utility>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/world.h"

namespace swarmsim::lua_host {

std::string MemoryLimitTail(const LuaMemory& memory) {
  return std::to_string(memory.limit >> 20) + " MiB of Lua memory (" + memory.setting + ")";
}

std::string ErrorText(lua_State* L, int status) {
  if (status == LUA_ERRMEM) {
    const auto* state = static_cast<const ScriptState*>(Context(L).host_state);
    if (state != nullptr && state->memory.refused)
      return std::string("an allocation would take ") + state->memory.holder + " past " +
             MemoryLimitTail(state->memory);
    return "not enough memory";
  }
  if (status != LUA_ERRRUN && status != LUA_ERRSYNTAX && status != LUA_ERRERR)
    return "internal error: a C++ exception crossed a Lua frame (please report this)";
  if (lua_type(L, -1) == LUA_TSTRING) return lua_tostring(L, -1);
  return std::string("(error object is a ") + luaL_typename(L, -1) + " value)";
}

void ThrowScriptError(const ScriptState& state, ObjectId object, std::string message,
                      std::string_view what) {
  lua_settop(state.L, 0);
  const Scene& scene = *state.context.scene;
  const std::string path = scene.IsValid(object)   ? scene.PathOf(object)
                           : state.context.is_main ? std::string("the main script")
                                                   : std::string("?");
  throw Error(state.context.name + ": " + message + " [in " + std::string(what) + " of " + path +
              "]");
}

bool Disable(ScriptState& state, Script& script, const std::string& error) {
  if (state.context.world->settings().on_script_error != ScriptErrorPolicy::kDisableScript ||
      state.context.is_main)
    return false;
  script.disabled = true;
  state.context.runtime->log.Add("error, script disabled: " + error);
  state.context.runtime->disabled.push_back(error);
  return true;
}

}  // namespace swarmsim::lua_host
