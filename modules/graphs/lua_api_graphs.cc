// sim.* graphs (the Lua area of the graph type):
//   sim.setGraphStreamValue(h, stream, value)  the value a script stream
//       records at the next sample (stream: its name, or the id
//       sim.addGraphStream returns); a robot's own graphs only (scene
//       scripts: any)
//   sim.addGraphStream(h, name) -> id  CoppeliaSim's call: the id of the
//       script stream `name` the world file declares ("script name")
//   sim.getGraphStreamValues(h, stream [, count]) -> times, values  the
//       samples a stream (any kind; a name or an id) recorded so far, the
//       last `count` of them (default: all kept), oldest first
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/graphs/module.h"

namespace swarmsim::graphs {

namespace {

GraphRow& GraphOf(lua_State* L, ObjectId* id_out) {
  Scene& scene = *Context(L).scene;
  const ObjectId id = CheckObject(L, 1);
  const uint32_t slot = scene.SlotOf(id);
  ObjectType type;
  if (!scene.FindType("graph", &type) || scene.type_at(slot) != type)
    throw Error("object " + scene.PathOf(id) + " is not a graph");
  *id_out = id;
  return static_cast<Rows<GraphRow>&>(*scene.rows(type)).rows[scene.row_at(slot)];
}

std::string ScriptStreams(const GraphRow& g) {
  std::string list;
  for (const StreamSpec& s : g.streams)
    if (s.kind == StreamKind::kScript) list += (list.empty() ? "'" : ", '") + s.name + "'";
  return list.empty() ? "it has none; declare one in the world file: streams: [\"script NAME\"]"
                      : "its script streams: " + list;
}

// The index of the stream argument 2 names (a name or a 1-based id): a
// script stream's unless `any`.
size_t StreamIndex(lua_State* L, const Scene& scene, ObjectId id, const GraphRow& g,
                   bool any = false) {
  if (lua_type(L, 2) == LUA_TNUMBER) {
    const lua_Integer k = ArgInteger(L, 2);
    if (k < 1 || k > static_cast<lua_Integer>(g.streams.size()) ||
        (!any && g.streams[k - 1].kind != StreamKind::kScript))
      throw Error("graph " + scene.PathOf(id) + " has no " + (any ? "" : "script ") +
                  "stream with id " + std::to_string(k) + " (it has " +
                  std::to_string(g.streams.size()) + " streams); " + ScriptStreams(g));
    return static_cast<size_t>(k - 1);
  }
  const std::string name = ArgString(L, 2);
  for (size_t i = 0; i < g.streams.size(); ++i) {
    if (g.streams[i].name != name) continue;
    if (!any && g.streams[i].kind != StreamKind::kScript)
      throw Error("stream '" + name + "' of graph " + scene.PathOf(id) +
                  " is not a script stream (it reads its object); " + ScriptStreams(g));
    return i;
  }
  std::string names;
  for (const StreamSpec& s : g.streams) names += (names.empty() ? "'" : ", '") + s.name + "'";
  throw Error("graph " + scene.PathOf(id) + " has no stream '" + name + "'; " +
              (any ? "its streams: " + names : ScriptStreams(g)));
}

int SetGraphStreamValue(lua_State* L) {
  const LuaContext& c = Context(L);
  ObjectId id;
  GraphRow& g = GraphOf(L, &id);
  const size_t i = StreamIndex(L, *c.scene, id, g);
  const double value = ArgNumber(L, 3);
  if (c.instance >= 0 && c.scene->instance_of(id) != c.instance)
    throw Error("a robot's script may set only its own graphs' streams ('" + c.scene->PathOf(id) +
                "' belongs to another robot or to the scene)");
  if (g.script_values.size() != g.streams.size()) g.script_values.assign(g.streams.size(), NAN);
  g.script_values[i] = value;
  return 0;
}

int AddGraphStream(lua_State* L) {
  const LuaContext& c = Context(L);
  ObjectId id;
  const GraphRow& g = GraphOf(L, &id);
  lua_pushinteger(L, static_cast<lua_Integer>(StreamIndex(L, *c.scene, id, g) + 1));
  return 1;
}

int GetGraphStreamValues(lua_State* L) {
  const LuaContext& c = Context(L);
  ObjectId id;
  const GraphRow& g = GraphOf(L, &id);
  const size_t stream = StreamIndex(L, *c.scene, id, g, /*any=*/true);
  lua_Integer count = -1;
  if (!lua_isnoneornil(L, 3)) {
    count = ArgInteger(L, 3);
    if (count < 0)
      throw Error("bad argument #3 (a count >= 0 expected, got " + std::to_string(count) + ")");
  }
  const auto* module = c.world != nullptr
                           ? dynamic_cast<const GraphModule*>(c.world->find_module(kModuleName))
                           : nullptr;
  const Series* series = module != nullptr ? module->Find(id) : nullptr;
  const size_t kept = series != nullptr ? series->count : 0;
  const size_t n = count < 0 ? kept : std::min(kept, static_cast<size_t>(count));
  lua_createtable(L, static_cast<int>(n), 0);
  lua_createtable(L, static_cast<int>(n), 0);
  for (size_t i = 0; i < n; ++i) {
    const double* sample = series->sample(kept - n + i);
    lua_pushnumber(L, sample[0]);
    lua_rawseti(L, -3, static_cast<lua_Integer>(i + 1));
    lua_pushnumber(L, sample[stream + 1]);
    lua_rawseti(L, -2, static_cast<lua_Integer>(i + 1));
  }
  return 2;
}

}  // namespace

void RegisterGraphApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setGraphStreamValue", Guarded<SetGraphStreamValue, "sim.setGraphStreamValue">},
      {"addGraphStream", Guarded<AddGraphStream, "sim.addGraphStream">},
      {"getGraphStreamValues", Guarded<GetGraphStreamValues, "sim.getGraphStreamValues">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::graphs
