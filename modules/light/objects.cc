// The `light_source` and `light_sensor` object types (light.h) and the
// module's registration.
#include <cstdio>
#include <memory>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/light/light.h"
#include "modules/light/module.h"

namespace swarmsim::light {

namespace {

constexpr double kDeg = 3.141592653589793 / 180;
// The bound on noise widths (the reading's units: intensity / m^2).
constexpr double kMaxNoise = 1e9;

constexpr ObjectKey kSourceKeys[] = {
    {"intensity", "1",
     "a non-negative number: a sensor 1 m away, facing it, reads this much (inverse-square "
     "law); scripts change it with sim.setLightSourceIntensity"},
    {"on", "true", "switched on from the start (sim.setLightSourceOn)"},
    {"color", "[1, 1, 1]", "RGB, each 0..1: the colour it is drawn in (sensors read intensity)"},
    {"radius", "0.02", "m, > 0: the glowing sphere it is drawn as"},
};

constexpr ObjectKey kSensorKeys[] = {
    {"fov_deg", "180",
     "field of view about its +x, above 0 and up to 360: the response falls linearly from 1 on "
     "the axis to 0 at half of it"},
    {"range", "0", "m, >= 0: lights farther away are not read (0: any distance)"},
    {"occlusion", "true", "static shapes and the environment map between it and a light hide it"},
    {"robot_occlusion", "false", "other robots' bodies (and dynamic shapes) hide lights too"},
    {"saturation", "0", ">= 0: the largest reading (0: no limit)"},
    {"noise", "0", "std dev of Gaussian noise added to the reading, >= 0"},
    {"noise_uniform", "0", "half width of uniform noise added to the reading, >= 0"},
    {"failure_probability", "0", "0..1: the chance that it reads 0 in a step"},
};

std::unique_ptr<RowTable> MakeSourceRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<LightSourceRow>>();
}
std::unique_ptr<RowTable> MakeSensorRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<LightSensorRow>>();
}

void ReadSource(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  LightSourceRow& l = *static_cast<LightSourceRow*>(row);
  if (r.Has("intensity")) l.intensity = r.Number("intensity", kNonNegative);
  if (r.Has("on")) l.on = r.Bool("on");
  if (r.Has("color")) l.settings.Edit().color = r.Vector3("color", kFraction);
  if (r.Has("radius")) l.settings.Edit().radius = r.Number("radius", kPositiveLength);
}

void ReadSensor(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  LightSensorRow& l = *static_cast<LightSensorRow*>(row);
  const auto edit = [&]() -> LightSensorSettings& { return l.settings.Edit(); };
  if (r.Has("fov_deg")) {
    const double a = r.Number("fov_deg", kAngleDeg);
    if (!(a > 0 && a <= 360)) {
      char message[120];
      std::snprintf(message, sizeof message,
                    "'fov_deg' must be an angle above 0 and up to 360 degrees (got %g)", a);
      r.Fail("fov_deg", message);
    }
    edit().fov = a * kDeg;
  }
  if (r.Has("range")) edit().range = r.Number("range", kNonNegativeLength);
  if (r.Has("occlusion")) edit().occlusion = r.Bool("occlusion");
  if (r.Has("robot_occlusion")) edit().robot_occlusion = r.Bool("robot_occlusion");
  if (r.Has("saturation")) edit().saturation = r.Number("saturation", kNonNegative);
  NoiseSettings noise = l.settings->noise;
  ReadNoise(r, "", kMaxNoise, &noise);
  if (noise.gaussian != l.settings->noise.gaussian || noise.uniform != l.settings->noise.uniform ||
      noise.failure != l.settings->noise.failure)
    edit().noise = noise;
}

void ScaleSource(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<LightSourceRow*>(row)->settings.Edit().radius *= s;
}
void ScaleSensor(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  LightSensorRow& l = *static_cast<LightSensorRow*>(row);
  if (l.settings->range > 0) l.settings.Edit().range *= s;
}

// What scripts change (and what sensors read next).
void HashSources(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<LightSourceRow>& rows = scene.rows<LightSourceRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].intensity);
    h->AddValue(rows.rows[r].on);
  }
}

// The readings scripts act on next.
void HashSensors(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<LightSensorRow>& rows = scene.rows<LightSensorRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].reading);
  }
}

// Snapshots: what HashSources and HashSensors add.
void SaveSources(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const LightSourceRow& l : scene.rows<LightSourceRow>(type).rows) {
    out->Put(l.intensity);
    out->Put<uint8_t>(l.on);
  }
}
void LoadSources(Scene* scene, ObjectType type, StateReader* in) {
  for (LightSourceRow& l : scene->rows<LightSourceRow>(type).rows) {
    l.intensity = in->Get<double>();
    l.on = in->GetBool();
  }
}
void SaveSensors(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const LightSensorRow& l : scene.rows<LightSensorRow>(type).rows) out->Put(l.reading);
}
void LoadSensors(Scene* scene, ObjectType type, StateReader* in) {
  for (LightSensorRow& l : scene->rows<LightSensorRow>(type).rows) l.reading = in->Get<double>();
}

// A glowing sphere in its colour while lit, dark otherwise.
void SourceVisual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const LightSourceRow& l = scene.rows<LightSourceRow>(type).rows[row];
  out->kind = VisualKind::kLight;
  out->size = {l.settings->radius, 0, 0};
  out->color = l.settings->color;
  out->on = l.lit();
}

constinit const ObjectTypeDescriptor kLightSourceType{
    .name = kLightSourceTypeName,
    .description = "a point light (intensity, on/off from scripts) that light sensors read",
    .make_rows = MakeSourceRows,
    .scale_row = ScaleSource,
    .hash_rows = HashSources,
    .keys = kSourceKeys,
    .read = ReadSource,
    .register_lua = RegisterLightApi,
    .visual = SourceVisual,
    .save_rows = SaveSources,
    .load_rows = LoadSources,
};

constinit const ObjectTypeDescriptor kLightSensorType{
    .name = kLightSensorTypeName,
    .description =
        "the light of the light sources along its +x: intensity / d^2, falling with the angle",
    .make_rows = MakeSensorRows,
    .scale_row = ScaleSensor,
    .hash_rows = HashSensors,
    .keys = kSensorKeys,
    .read = ReadSensor,
    .register_lua = RegisterLightApi,
    .save_rows = SaveSensors,
    .load_rows = LoadSensors,
};

}  // namespace

bool FindSensorType(const Scene& scene, ObjectType* type) {
  return scene.FindType(kLightSensorTypeName, type);
}

std::span<const LightSensorRow> Sensors(const Scene& scene, std::span<const uint32_t>* owners) {
  ObjectType type;
  if (!FindSensorType(scene, &type)) {
    *owners = {};
    return {};
  }
  const Rows<LightSensorRow>& rows = scene.rows<LightSensorRow>(type);
  *owners = rows.owners;
  return rows.rows;
}

const LightSensorRow* FindSensor(const Scene& scene, ObjectId id) {
  ObjectType type;
  if (!FindSensorType(scene, &type) || !scene.IsValid(id)) return nullptr;
  const uint32_t slot = scene.SlotOf(id);
  if (scene.type_at(slot) != type) return nullptr;
  return &scene.rows<LightSensorRow>(type).rows[scene.row_at(slot)];
}

int LightSensingModule::ReadValue(const Scene& scene, ObjectId id, double* value) const noexcept {
  // The type the sense phase found, once there was one (no search by name).
  const LightSensorRow* sensor = nullptr;
  if (!types_found_) {
    sensor = FindSensor(scene, id);
  } else if (have_types_ && scene.IsValid(id) && scene.type_at(scene.SlotOf(id)) == sensor_type_) {
    sensor = &scene.rows<LightSensorRow>(sensor_type_).rows[scene.row_at(scene.SlotOf(id))];
  }
  if (sensor == nullptr) return -1;
  *value = sensor->reading;
  return 0;
}

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"sensor", kModuleName, "1.0",
        "light sources and light sensors: intensity / d^2 with an angular response, occlusion by "
        "shapes, the map and (a setting) robots (light_source, light_sensor types)"},
       PhaseBit(Phase::kSense),
       130,
       /*every_world=*/true,
       [](World*, const void*) -> std::unique_ptr<Module> {
         return std::make_unique<LightSensingModule>();
       },
       nullptr});
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kLightSourceType));
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kLightSensorType));
}

}  // namespace swarmsim::light
