// sim.* graphs (the Lua area of the graph type):
//   sim.setGraphStreamValue(h, stream, value)  the value a script stream
//       records at the next sample (stream: its name, or the id
//       sim.addGraphStream returns); a robot's own graphs only (scene
//       scripts: any)
//   sim.addGraphStream(h, name) -> id  CoppeliaSim's call: the id of the
//       script stream `name` the world file declares ("script name")
#include <cmath>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/scene.h"
#include "modules/graphs/rows.h"

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

// The index of the script stream argument 2 names (a name or an id).
size_t StreamIndex(lua_State* L, const Scene& scene, ObjectId id, const GraphRow& g) {
  if (lua_type(L, 2) == LUA_TNUMBER) {
    const lua_Integer k = ArgInteger(L, 2);
    if (k < 1 || k > static_cast<lua_Integer>(g.streams.size()) ||
        g.streams[k - 1].kind != StreamKind::kScript)
      throw Error("graph " + scene.PathOf(id) + " has no script stream with id " +
                  std::to_string(k) + "; " + ScriptStreams(g));
    return static_cast<size_t>(k - 1);
  }
  const std::string name = ArgString(L, 2);
  for (size_t i = 0; i < g.streams.size(); ++i) {
    if (g.streams[i].name != name) continue;
    if (g.streams[i].kind != StreamKind::kScript)
      throw Error("stream '" + name + "' of graph " + scene.PathOf(id) +
                  " is not a script stream (it reads its object); " + ScriptStreams(g));
    return i;
  }
  throw Error("graph " + scene.PathOf(id) + " has no stream '" + name + "'; " + ScriptStreams(g));
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

}  // namespace

void RegisterGraphApi(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"setGraphStreamValue", Guarded<SetGraphStreamValue, "sim.setGraphStreamValue">},
      {"addGraphStream", Guarded<AddGraphStream, "sim.addGraphStream">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

}  // namespace swarmsim::graphs
