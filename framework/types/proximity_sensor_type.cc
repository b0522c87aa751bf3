// proximity_sensor: a ray along the sensor's +z axis that reports the
// nearest shape within its range (modules/proximity senses it).
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/types/core_types.h"

namespace swarmsim {

// Its Lua API area (framework/lua_api_*.cc).
void RegisterSensorsApi(lua_State* L);

namespace {

constexpr ObjectKey kKeys[] = {
    {"range", "0.1", "m, > 0"},
};

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<ProximitySensorData>>();
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  ProximitySensorData& p = *static_cast<ProximitySensorData*>(row);
  p.range *= s;
  p.distance *= s;
}

void Hash(const Scene& scene, ObjectType, StateHasher* h) {
  for (size_t r = 0; r < scene.proximity_sensors().size(); ++r) {
    const ProximitySensorData& p = scene.proximity_sensors()[r];
    h->AddValue(scene.proximity_sensor_owners()[r]);
    h->AddValue(p.detected);
    h->AddValue(p.distance);
    h->AddValue(p.p_SD());
    h->AddValue(p.detected_object);
  }
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  if (r.Has("range"))
    static_cast<ProximitySensorData*>(row)->range = r.Number("range", kPositiveLength);
}

}  // namespace

constinit const ObjectTypeDescriptor kProximitySensorType{
    .name = "proximity_sensor",
    .description = "a ray sensor along its +z axis: the nearest shape within its range",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterSensorsApi,
};

}  // namespace swarmsim
