// The ground_sensor type: its rows, keys, reader, scale, hash and visual,
// and its Lua area (sim.readGroundSensor, sim.readGroundSensors).
#include <memory>
#include <string>

#include "framework/error.h"
#include "framework/lua_api.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/ground_sensor/ground_sensor.h"

namespace swarmsim::ground_sensor {

void RegisterModule(ModuleRegistry* registry);  // module.cc

namespace {

// --- The type: rows, keys, reader, scale, hash, visual ---------------------------

constexpr ObjectKey kKeys[] = {
    {"mode", "grey", "color (r, g, b), grey (0.299 r + 0.587 g + 0.114 b) or binary (0 or 1)"},
    {"threshold", "0.5", "binary: reads 1 when the grey level is at or above it, else 0; 0..1"},
    {"noise", "0",
     "std dev of Gaussian noise on the grey level (each channel in colour mode), 0..1"},
    {"noise_uniform", "0", "half width of uniform noise, as `noise`, 0..1"},
    {"failure_probability", "0", "probability 0..1 that it reads nothing (0, black) in a step"},
    {"disc_radius", "0.005", "m, the size of the disc it is drawn as (snapshots, viewer)"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<GroundSensorRow>>();
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  GroundSensorSettings& s = static_cast<GroundSensorRow*>(row)->settings.Edit();
  if (r.Has("disc_radius")) s.radius = r.Number("disc_radius", kPositiveLength);
  if (r.Has("mode")) {
    const std::string mode = r.Choice("mode", {"color", "grey", "binary"});
    s.mode = mode == "color" ? Mode::kColor : mode == "grey" ? Mode::kGrey : Mode::kBinary;
  }
  if (r.Has("threshold")) {
    if (s.mode != Mode::kBinary)
      r.FailAtKey("threshold", "'threshold' is for 'mode: binary' (this sensor's mode is " +
                                   std::string(s.mode == Mode::kColor ? "color" : "grey") + ")");
    s.threshold = r.Number("threshold", kFraction);
  }
  ReadNoise(r, "", 1.0, &s.noise);
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<GroundSensorRow*>(row)->settings.Edit().radius *= s;
}

// What the scripts read next.
void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<GroundSensorRow>& rows = scene.rows<GroundSensorRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].color);
    h->AddValue(rows.rows[r].value);
  }
}

// Snapshots (framework/world_state.h): the readings.
void Save(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const GroundSensorRow& g : scene.rows<GroundSensorRow>(type).rows) {
    out->Put(g.color);
    out->Put(g.value);
  }
}

void Load(Scene* scene, ObjectType type, StateReader* in) {
  for (GroundSensorRow& g : scene->rows<GroundSensorRow>(type).rows) {
    g.color = in->Get<Vec3>();
    g.value = in->Get<double>();
  }
}

// A thin disc in the colour it sees.
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const GroundSensorRow& g = scene.rows<GroundSensorRow>(type).rows[row];
  out->kind = VisualKind::kCylinder;
  out->size = {g.settings->radius, 0, 0.002};
  out->color = g.color;
}

// --- Its Lua area ------------------------------------------------------------------

const GroundSensorRow& SensorOf(const Scene& scene, ObjectId id) {
  ObjectType type;
  if (!FindSensorType(scene, &type)) throw Error("this world has no ground sensors");
  return scene.row<GroundSensorRow>(type, id, "ground sensor");
}

// sim.readGroundSensor(h) -> value, r, g, b: the value read (colour: its
// grey level; grey: 0..1; binary: 0 or 1) and the colour seen (grey and
// binary sensors: value, value, value), each 0..1, at this step's sense phase.
int ReadGroundSensor(lua_State* L) {
  const GroundSensorRow& g = SensorOf(*Context(L).scene, CheckObject(L, 1));
  for (const double v : {g.value, g.color.x, g.color.y, g.color.z}) lua_pushnumber(L, v);
  return 4;
}

// sim.readGroundSensors(handles [, values]) -> values: the value each sensor
// of the array `handles` reads, as sim.readGroundSensor's first result,
// into `values` (entries 1 .. #handles overwritten; reused from step to step,
// the call allocates nothing) or into a new table when it is absent or nil.
int ReadGroundSensors(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  FillFromHandles(L, [&](ObjectId id) { lua_pushnumber(L, SensorOf(scene, id).value); });
  return 1;
}

void RegisterLua(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readGroundSensor", Guarded<ReadGroundSensor, "sim.readGroundSensor">},
      {"readGroundSensors", Guarded<ReadGroundSensors, "sim.readGroundSensors">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

constinit const ObjectTypeDescriptor kGroundSensorType{
    .name = kTypeName,
    .description = "the floor under it: colour, grey level or binary (the floor: section, paint)",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterLua,
    .visual = Visual,
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace

bool FindSensorType(const Scene& scene, ObjectType* type) {
  return scene.FindType(kTypeName, type);
}

void Register(ModuleRegistry* registry) {
  RegisterModule(registry);
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kGroundSensorType));
}

}  // namespace swarmsim::ground_sensor
