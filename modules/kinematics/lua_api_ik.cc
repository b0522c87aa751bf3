// sim.* IK groups, the "ik" module's Lua area (ik_groups.h):
//   sim.getIkGroup(name [, {noError = true}]) -> handle (-1 with noError)
//       a group of the calling script's robot (scene scripts: scene groups)
//   sim.handleIkGroup(h) -> status   solves now and applies the result;
//       sim.ikresult_not_performed (0), sim.ikresult_success (1), sim.ikresult_fail (2)
//   sim.getIkGroupStatus(h) -> status of the group's last solve
// Groups are solved automatically each step in the actuate phase unless
// declared `automatic: false`; a robot's scripts handle only its own groups.
#include <climits>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/world.h"
#include "modules/kinematics/ik_groups.h"

namespace swarmsim::kinematics {
namespace {

IkGroups* Module(const LuaContext& c, bool required) {
  IkGroups* module = FindIkGroups(*c.world);
  if (!module && required) throw Error("the world has no IK groups");
  return module;
}

int CheckGroup(lua_State* L, const LuaContext& c, IkGroups* module) {
  const lua_Integer h = ArgInteger(L, 1);
  if (h < 0 || h > INT_MAX || !module->IsLive(static_cast<int>(h)))  // (g + 2^32 is not g)
    throw Error("no IK group with handle " + std::to_string(h) +
                " (it was removed with its model, or never existed)");
  if (c.instance >= 0 && module->instance_of(static_cast<int>(h)) != c.instance)
    throw Error("IK group '" + module->spec(static_cast<int>(h)).name +
                "' belongs to another robot; only its own scripts can handle it");
  return static_cast<int>(h);
}

int GetIkGroup(lua_State* L) {
  const LuaContext& c = Context(L);
  const std::string name = ArgString(L, 1);
  bool no_error = false;
  if (lua_istable(L, 2)) {
    lua_pushliteral(L, "noError");  // raw: no metamethod may raise here
    lua_rawget(L, 2);
    no_error = lua_toboolean(L, -1);
    lua_pop(L, 1);
  }
  IkGroups* module = Module(c, false);
  const int h = module ? module->FindGroup(name, c.instance) : 0;
  if (h == 0 && !no_error)
    throw Error("no IK group '" + name + "' in " + (c.instance >= 0 ? c.name : "the scene"));
  lua_pushinteger(L, h == 0 ? -1 : h);
  return 1;
}

int HandleIkGroup(lua_State* L) {
  const LuaContext& c = Context(L);
  IkGroups* module = Module(c, true);
  const int h = CheckGroup(L, c, module);
  lua_pushinteger(L, static_cast<lua_Integer>(module->Handle(h, c.scene)));
  return 1;
}

int GetIkGroupStatus(lua_State* L) {
  const LuaContext& c = Context(L);
  IkGroups* module = Module(c, true);
  lua_pushinteger(L, static_cast<lua_Integer>(module->last_status(CheckGroup(L, c, module))));
  return 1;
}

}  // namespace

void RegisterIkApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"getIkGroup", Guarded<GetIkGroup, "sim.getIkGroup">},
      {"handleIkGroup", Guarded<HandleIkGroup, "sim.handleIkGroup">},
      {"getIkGroupStatus", Guarded<GetIkGroupStatus, "sim.getIkGroupStatus">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
  lua_pushinteger(L, static_cast<lua_Integer>(IkStatus::kNotPerformed));
  lua_setfield(L, -2, "ikresult_not_performed");
  lua_pushinteger(L, static_cast<lua_Integer>(IkStatus::kSolved));
  lua_setfield(L, -2, "ikresult_success");
  lua_pushinteger(L, static_cast<lua_Integer>(IkStatus::kFailed));
  lua_setfield(L, -2, "ikresult_fail");
}

}  // namespace swarmsim::kinematics
