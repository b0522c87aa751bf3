// sim.* collision and distance (the Lua area of the distance type):
//   sim.checkCollision(a, b) -> 1 or 0, {h1, h2} (CoppeliaSim's)
//   sim.checkDistance(a, b [, threshold]) -> result (0/1), {x1, y1, z1, x2, y2, z2, d}, {h1, h2}
//   sim.readDistance(h) -> d or nil, {x1, y1, z1, x2, y2, z2}, {h1, h2}
//   sim.readCollision(h) -> 1 or 0, {h1, h2}, contacts {{x, y, z}, ...}
// `a` is an object (with everything below it), a collection object or a
// script's collection; `b` the same, 'environment' or 'everything_else'.
// Checks run on the poses of the step's start, robots in parallel.
#include <cmath>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/world.h"
#include "modules/collision/module.h"
#include "modules/collision/rows.h"

namespace swarmsim::collision {

namespace {

CollisionModule& ModuleOf(lua_State* L) {
  const LuaContext& c = Context(L);
  auto* module = c.world != nullptr
                     ? dynamic_cast<CollisionModule*>(c.world->find_module(kModuleName))
                     : nullptr;
  if (module == nullptr) throw Error("the collision module is not running in this world");
  return *module;
}

struct Sides {
  std::vector<uint32_t> a, b;
  Target target;
};

Sides ReadSides(lua_State* L, const Geometry& geometry) {
  const Scene& scene = *Context(L).scene;
  Sides s;
  s.a = geometry.ShapesOf(scene, CollectionArgSlots(L, 1));
  if (lua_type(L, 2) == LUA_TSTRING) {
    const std::string text = lua_tostring(L, 2);
    const EntitySpec e = ParseEntity(text);
    if (e.kind == EntitySpec::kPath)
      throw Error("bad argument #2 ('environment', 'everything_else' or a handle expected, got '" +
                  text + "')");
    s.target.kind = e.kind;
  } else {
    s.b = geometry.ShapesOf(scene, CollectionArgSlots(L, 2));
  }
  s.target.slots = s.b;
  if (s.target.kind == EntitySpec::kPath && s.a == s.b && !s.a.empty())
    throw Error("the two entities are the same objects: nothing to measure between them");
  return s;
}

void PushHandlePair(lua_State* L, const Scene& scene, uint32_t s1, uint32_t s2) {
  lua_createtable(L, 2, 0);
  const uint32_t slots[2] = {s1, s2};
  for (int i = 0; i < 2; ++i) {
    lua_pushinteger(L, slots[i] < scene.slot_count() ? scene.IdAt(slots[i]).ToInteger() : -1);
    lua_rawseti(L, -2, i + 1);
  }
}

void PushHandlePair(lua_State* L, ObjectId o1, ObjectId o2) {
  lua_createtable(L, 2, 0);
  lua_pushinteger(L, o1.IsNull() ? -1 : o1.ToInteger());
  lua_rawseti(L, -2, 1);
  lua_pushinteger(L, o2.IsNull() ? -1 : o2.ToInteger());
  lua_rawseti(L, -2, 2);
}

int CheckCollision(lua_State* L) {
  CollisionModule& module = ModuleOf(L);
  const Geometry& geometry = module.Fresh(*Context(L).world);
  const Sides s = ReadSides(L, geometry);
  const CollisionAnswer c = geometry.Collide(s.a, s.target, 0);
  lua_pushinteger(L, c.colliding ? 1 : 0);
  PushHandlePair(L, *Context(L).scene, c.s1, c.s2);
  return 2;
}

int CheckDistance(lua_State* L) {
  CollisionModule& module = ModuleOf(L);
  const Geometry& geometry = module.Fresh(*Context(L).world);
  const Sides s = ReadSides(L, geometry);
  double threshold = INFINITY;
  if (!lua_isnoneornil(L, 3)) {
    threshold = ArgNumber(L, 3);
    if (!(threshold > 0)) throw Error("bad argument #3 (a positive threshold expected)");
  }
  const DistanceAnswer d = geometry.Distance(s.a, s.target, threshold, kNoSlot, kNoSlot);
  lua_pushinteger(L, d.found ? 1 : 0);
  const double data[7] = {d.p1.x, d.p1.y, d.p1.z, d.p2.x, d.p2.y, d.p2.z, d.distance};
  PushNumberArray(L, data, 7);
  PushHandlePair(L, *Context(L).scene, d.s1, d.s2);
  return 3;
}

template <typename Row>
const Row& RowOf(lua_State* L, const char* type_name) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType(type_name, &type) || scene.type_at(slot) != type)
    throw Error("object " + scene.PathOf(id) + " is not a " + type_name + " object");
  return static_cast<const Rows<Row>&>(*scene.rows(type)).rows[scene.row_at(slot)];
}

int ReadDistance(lua_State* L) {
  const DistanceRow& d = RowOf<DistanceRow>(L, "distance");
  if (!d.found) {
    lua_pushnil(L);
    return 1;
  }
  lua_pushnumber(L, d.distance);
  const double points[6] = {d.p1.x, d.p1.y, d.p1.z, d.p2.x, d.p2.y, d.p2.z};
  PushNumberArray(L, points, 6);
  PushHandlePair(L, d.o1, d.o2);
  return 3;
}

int ReadCollision(lua_State* L) {
  const CollisionRow& c = RowOf<CollisionRow>(L, "collision");
  lua_pushinteger(L, c.colliding ? 1 : 0);
  PushHandlePair(L, c.o1, c.o2);
  lua_createtable(L, static_cast<int>(c.contact_points.size()), 0);
  for (size_t i = 0; i < c.contact_points.size(); ++i) {
    const Vec3& p = c.contact_points[i];
    const double xyz[3] = {p.x, p.y, p.z};
    PushNumberArray(L, xyz, 3);
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 3;
}

}  // namespace

void RegisterCollisionApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"checkCollision", Guarded<CheckCollision, "sim.checkCollision">},
      {"checkDistance", Guarded<CheckDistance, "sim.checkDistance">},
      {"readDistance", Guarded<ReadDistance, "sim.readDistance">},
      {"readCollision", Guarded<ReadCollision, "sim.readCollision">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::collision
