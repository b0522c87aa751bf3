#include "tests/modules/ground_sensor/ground_sensor.h"

#include <memory>

#include "framework/floor_layer.h"
#include "framework/lua_api.h"
#include "framework/module.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world.h"

namespace swarmsim::ground_sensor {
namespace {

// --- The type: rows, key, reader, scale, hash, visual --------------------------

constexpr ObjectKey kKeys[] = {
    {"radius", "0.005", "m, the size of the disc it is drawn as"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<GroundSensorRow>>();
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  if (r.Has("radius"))
    static_cast<GroundSensorRow*>(row)->settings.Edit().radius = r.Number("radius", kPositive);
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<GroundSensorRow*>(row)->settings.Edit().radius *= s;
}

// What the scripts read next.
void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<GroundSensorRow>& rows = scene.rows<GroundSensorRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].seen);
  }
}

// A thin disc in the colour it sees.
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const GroundSensorRow& g = scene.rows<GroundSensorRow>(type).rows[row];
  out->kind = VisualKind::kCylinder;
  out->size = {g.settings->radius, 0, 0.002};
  out->color = g.seen;
}

// --- Its Lua area ------------------------------------------------------------------

// sim.readGroundSensor(h) -> r, g, b: the floor's colour under it (0..1).
int ReadGroundSensor(lua_State* L) {
  const Scene& scene = *Context(L).scene;
  ObjectType type;
  scene.FindType(kTypeName, &type);  // registered with this function
  const GroundSensorRow& g = scene.row<GroundSensorRow>(type, CheckObject(L, 1), "ground sensor");
  for (const double c : {g.seen.x, g.seen.y, g.seen.z}) lua_pushnumber(L, c);
  return 3;
}

void RegisterLua(lua_State* L) {
  static constexpr luaL_Reg kFunctions[] = {
      {"readGroundSensor", Guarded<ReadGroundSensor, "sim.readGroundSensor">},
      {nullptr, nullptr},
  };
  luaL_setfuncs(L, kFunctions, 0);
}

constinit const ObjectTypeDescriptor kGroundSensorType{
    .name = kTypeName,
    .description = "the colour of the floor under it (the floor layer: paint)",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterLua,
    .visual = Visual,
};

// --- Its module: the sense phase -------------------------------------------------

// The floor layer's colour at (x, y): its background outside its area; black
// without a floor layer.
Vec3 FloorColorAt(const FloorLayer* floor, double x, double y) {
  if (floor == nullptr) return {};
  const FloorArea a = floor->floor_area();
  const int c = static_cast<int>((x - a.min_x) / a.resolution);
  const int r = static_cast<int>((a.max_y - y) / a.resolution);
  if (!(x >= a.min_x && y <= a.max_y) || c >= a.width || r >= a.height) return a.background;
  const uint8_t* rgb = &floor->floor_rgb()[3 * (static_cast<size_t>(r) * a.width + c)];
  return {rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0};
}

class Sensing final : public Module {
 public:
  void Sense(World* world) override {
    Scene& scene = world->scene();
    ObjectType type;
    if (!scene.FindType(kTypeName, &type)) return;
    Rows<GroundSensorRow>& rows = scene.rows<GroundSensorRow>(type);
    for (size_t r = 0; r < rows.size(); ++r) {
      const Vec3 p = scene.world_pose_at(rows.owners[r]).p;
      rows.rows[r].seen = FloorColorAt(world->floor_layer(), p.x, p.y);
    }
  }
};

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"sensor", "ground_sensor", "1.0", "the floor's colour under each ground sensor"},
       PhaseBit(Phase::kSense),
       120,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<Sensing>(); },
       nullptr});
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kGroundSensorType));
}

}  // namespace swarmsim::ground_sensor
