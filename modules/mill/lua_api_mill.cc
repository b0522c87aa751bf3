// sim.* mills and cuttables (the Lua area of the mill type):
//   sim.setMillEnabled(h, enabled)  a robot's own mills only (scene scripts: any)
//   sim.readMill(h) -> removed this step, removed in total (m^3; the last
//                      step's cut: after physics)
//   sim.readCuttable(h) -> voxels left, voxels at the start, volume left (m^3)
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/mill/rows.h"

namespace swarmsim::mill {

namespace {

template <typename Row>
Row& RowOf(lua_State* L, const char* type_name, ObjectId* id_out = nullptr) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(type_name, &type) || scene.type_at(slot) != type)
    throw Error("object " + scene.PathOf(id) + " is not a " + type_name);
  if (id_out != nullptr) *id_out = id;
  return static_cast<Rows<Row>&>(*scene.rows(type)).rows[scene.row_at(slot)];
}

int SetMillEnabled(lua_State* L) {
  const LuaContext& c = Context(L);
  ObjectId id;
  MillRow& mill = RowOf<MillRow>(L, "mill", &id);
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("a robot's script may switch only its own mills ('" + c.scene->PathOf(id) +
                "' belongs to another robot or to the scene)");
  ArgType(L, 2, LUA_TBOOLEAN);
  mill.enabled = lua_toboolean(L, 2) != 0;
  return 0;
}

int ReadMill(lua_State* L) {
  const MillRow& mill = RowOf<MillRow>(L, "mill");
  lua_pushnumber(L, mill.removed);
  lua_pushnumber(L, mill.removed_total);
  return 2;
}

int ReadCuttable(lua_State* L) {
  const CuttableRow& c = RowOf<CuttableRow>(L, "cuttable");
  lua_pushinteger(L, c.remaining);
  lua_pushinteger(L, c.voxel_count());
  lua_pushnumber(L, static_cast<double>(c.remaining) * c.voxel_volume());
  return 3;
}

}  // namespace

void RegisterMillApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setMillEnabled", Guarded<SetMillEnabled, "sim.setMillEnabled">},
      {"readMill", Guarded<ReadMill, "sim.readMill">},
      {"readCuttable", Guarded<ReadCuttable, "sim.readCuttable">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::mill
