// sim.* paint nozzles, the paint_nozzle type's Lua area (paint_nozzle.h).
//
// The paint layer reads nozzles in the record phase, after every script has
// run, so a robot's writes to its own nozzles are race-free. Writing another
// robot's nozzle would depend on the order robots run in, so it is an error.
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/paint/paint_nozzle.h"

namespace swarmsim::paint {
namespace {

// sim.setPaintNozzle(h, enabled [, {r, g, b}]): switches a paint nozzle on or
// off and optionally sets its colour (each component 0..1).
int SetPaintNozzle(lua_State* L) {
  const LuaContext& c = Context(L);
  Scene& scene = *c.scene;
  const ObjectId id = CheckObject(L, 1);
  ObjectType type;
  if (!scene.FindType(kPaintNozzleTypeName, &type))
    throw Error("the scene has no paint nozzle type (modules/paint is not registered)");
  PaintNozzleData& nozzle = scene.row<PaintNozzleData>(type, id, "paint nozzle");
  if (c.instance >= 0 && scene.instance_of(id) != c.instance)
    throw Error("a robot's script may set only its own paint nozzles ('" + scene.PathOf(id) +
                "' belongs to another robot or to the scene)");
  ArgType(L, 2, LUA_TBOOLEAN);
  const bool enabled = lua_toboolean(L, 2) != 0;
  const Vec3 color = lua_isnoneornil(L, 3) ? nozzle.color : ArgColor(L, 3);
  nozzle.enabled = enabled;
  nozzle.color = color;
  return 0;
}

}  // namespace

void RegisterPaintApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setPaintNozzle", Guarded<SetPaintNozzle, "sim.setPaintNozzle">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::paint
