// The `graph` object type (rows.h) and the module's registration.
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "modules/graphs/graphs.h"
#include "modules/graphs/module.h"
#include "modules/graphs/rows.h"

namespace swarmsim::graphs {

// The Lua area of the type (lua_api_graphs.cc).
void RegisterGraphApi(lua_State* L);

namespace {

constexpr ObjectKey kGraphKeys[] = {
    {"streams", "required",
     "list of streams, each \"[NAME =] KIND [PATH] [COMPONENT]\" (see below), "
     "e.g. [\"position :/body z\", \"speed = script\"]"},
    {"kind", "time",
     "time (every stream against time), xy (an X/Y curve: two streams) or xyz (a 3D curve: "
     "three streams)"},
    {"every", "1", "steps between samples, 1..1000000"},
    {"buffer", "100000", "samples kept, 1..10000000"},
    {"cyclic", "false", "when the buffer is full keep the last samples (false: the first)"},
    {"png", "true", "draw the graph as a PNG (gnuplot) besides its CSV"},
    {"title", "the graph's path", "the PNG's title"},
};

void ReadGraph(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  GraphRow& g = *static_cast<GraphRow*>(row);
  g.where = r.Where("streams");
  const std::vector<std::string> texts = r.Strings("streams", 1000, /*required=*/true);
  if (texts.empty()) r.Fail("streams", "a graph needs at least one stream");
  for (const std::string& text : texts) {
    try {
      ParseStream(text, &g.streams);
    } catch (const Error& e) {
      r.Fail("streams", e.what());
    }
  }
  std::set<std::string> names;
  for (const StreamSpec& s : g.streams)
    if (!names.insert(s.name).second)
      r.Fail("streams",
             "two streams are named '" + s.name + "'; name one of them: \"other = ...\"");
  if (r.Has("kind")) {
    const std::string kind = r.Choice("kind", {"time", "xy", "xyz"});
    g.kind = kind == "xy" ? GraphKind::kXy : kind == "xyz" ? GraphKind::kXyz : GraphKind::kTime;
  }
  const size_t want = g.kind == GraphKind::kXy ? 2 : g.kind == GraphKind::kXyz ? 3 : 0;
  if (want != 0 && g.streams.size() != want)
    r.Fail("streams", std::string("a kind: ") + (want == 2 ? "xy" : "xyz") + " graph takes " +
                          std::to_string(want) + " streams (" +
                          (want == 2 ? "x, y"
                                     : "x, y, z: one position without a component "
                                       "gives all three") +
                          "), got " + std::to_string(g.streams.size()));
  if (r.Has("every")) g.every = static_cast<int>(r.Integer("every", 1, 1000000));
  if (r.Has("buffer")) g.buffer = r.Integer("buffer", 1, 10000000);
  if (r.Has("cyclic")) g.cyclic = r.Bool("cyclic");
  if (r.Has("png")) g.png = r.Bool("png");
  if (r.Has("title")) g.title = r.String("title");
  g.script_values.assign(g.streams.size(), NAN);
}

// A copy records afresh: its settings, no script values.
void CopyGraph(const void* source, void* row) {
  const GraphRow& from = *static_cast<const GraphRow*>(source);
  GraphRow& to = *static_cast<GraphRow*>(row);
  to = from;
  to.script_values.assign(from.streams.size(), NAN);
}

void CheckGraph(const Scene& scene, ObjectId id, const void* row) {
  const GraphRow& g = *static_cast<const GraphRow*>(row);
  for (const StreamSpec& s : g.streams) {
    if (s.kind == StreamKind::kScript) continue;
    std::string problem;
    const ObjectId target = ResolveStream(scene, id, s, &problem);
    if (target.IsNull())
      throw Error((g.where.empty() ? "" : g.where + ": ") + "graph " + scene.PathOf(id) +
                  ": stream '" + s.name + "': " + problem);
  }
}

std::shared_ptr<const ObjectTypeDescriptor> GraphType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "graph";
  t->description = "a graph recording data streams after each step (CSV and PNG at the end)";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<GraphRow>>();
  };
  t->copy_row = CopyGraph;
  t->keys = kGraphKeys;
  t->read = ReadGraph;
  t->check = CheckGraph;
  t->register_lua = RegisterGraphApi;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"record", kModuleName, "1.0",
        "graph objects: data streams sampled after each step, written as CSV and PNG "
        "(gnuplot) into <out>/graphs/"},
       PhaseBit(Phase::kRecord),
       300,
       /*every_world=*/true,
       [](World* world, const void*) { return std::make_unique<GraphModule>(world); }});
  registry->RegisterObjectType(GraphType());
}

}  // namespace swarmsim::graphs
