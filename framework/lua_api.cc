// The sim.* API: helpers shared by the API areas, and the one list of areas.
#include "framework/lua_api.h"

namespace swarmsim {

void RaiseError(lua_State* L, const std::string& message) {
  luaL_where(L, 1);
  lua_pushlstring(L, message.data(), message.size());
  lua_concat(L, 2);
  lua_error(L);
  __builtin_unreachable();  // lua_error throws
}

ObjectId OptRelativeTo(lua_State* L, int arg) {
  if (lua_isnoneornil(L, arg)) return {};
  const lua_Integer h = luaL_checkinteger(L, arg);
  if (h == kHandleWorld) return {};
  return ObjectId::FromInteger(h);
}

void PushNumberArray(lua_State* L, const double* v, int n) {
  lua_createtable(L, n, 0);
  for (int i = 0; i < n; ++i) {
    lua_pushnumber(L, v[i]);
    lua_rawseti(L, -2, i + 1);
  }
}

void RegisterAllApis(lua_State* L) {
  // One API area per file; a new area adds one line here.
  static constexpr void (*kAreas[])(lua_State*) = {
      RegisterSimApi,      // lua_api_sim.cc: time, parameters, random, metrics, print
      RegisterObjectsApi,  // lua_api_objects.cc: lookup, names, tree, poses
      RegisterJointsApi,   // lua_api_joints.cc: joint targets and states
      RegisterSensorsApi,  // lua_api_sensors.cc: proximity sensors
      RegisterMessagesApi, // lua_api_messages.cc: messages, signals, packing
      RegisterControlApi,  // script_host.cc: child scripts, threads, main-script handlers
      RegisterDynamicsApi,  // lua_api_dynamics.cc: dynamic/kinematic switch, joint forces
  };
  lua_newtable(L);
  lua_pushinteger(L, kHandleWorld);
  lua_setfield(L, -2, "handle_world");
  for (auto area : kAreas) area(L);
  lua_setglobal(L, "sim");
}

}  // namespace swarmsim
