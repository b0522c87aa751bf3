// The `led` and `blob_camera` object types (leds.h, blob_camera.h) and the
// module's registration.
#include <cstdio>
#include <memory>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/blobs/blob_camera.h"
#include "modules/blobs/blobs.h"
#include "modules/blobs/leds.h"
#include "modules/blobs/module.h"

namespace swarmsim::blobs {

// The Lua area of both types (lua_api_blobs.cc).
void RegisterBlobsApi(lua_State* L);

namespace {

constexpr double kDeg = 3.141592653589793 / 180;

constexpr ObjectKey kLedKeys[] = {
    {"color", "[1, 1, 1]", "RGB, each 0..1 (black: emits nothing, cameras do not see it)"},
    {"on", "true", "switched on from the start"},
    {"radius", "0.01", "m, > 0: how big it is drawn (cameras see its centre)"},
};

constexpr ObjectKey kCameraKeys[] = {
    {"range", "1", "m, > 0: LEDs farther from the camera's origin are not seen"},
    {"fov_deg", "360",
     "horizontal field of view about the camera's +x, above 0 and up to 360 "
     "(360: omnidirectional)"},
    {"vertical_fov_deg", "180",
     "LEDs within half of it above or below the camera's xy plane "
     "are seen; above 0 and up to 180 (180: all)"},
    {"occlusion", "true", "shapes between the camera and an LED hide it"},
    {"angle_noise_deg", "0", "std dev of Gaussian noise added to bearing and elevation, 0..90"},
    {"distance_noise", "0", "std dev of Gaussian noise on distance, as a fraction of it, 0..1"},
    {"failure_probability", "0", "0..1: chance that the camera sees nothing in a step"},
    {"enabled", "true", "off: the camera sees nothing"},
};

void ReadLed(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  LedRow& led = *static_cast<LedRow*>(row);
  if (r.Has("color")) led.color = r.Vector3("color", kFraction);
  if (r.Has("on")) led.on = r.Bool("on");
  if (r.Has("radius")) led.radius = r.Number("radius", kPositiveLength);
}

// An angle in degrees, above 0 and up to `max_deg`, in rad.
double ReadAperture(const ObjectReader& r, const char* key, double max_deg) {
  const double a = r.Number(key, kAngleDeg);
  if (!(a > 0 && a <= max_deg)) {
    char message[160];
    std::snprintf(message, sizeof message,
                  "'%s' must be an angle above 0 and up to %g degrees (got %g)", key, max_deg, a);
    r.Fail(key, message);
  }
  return a * kDeg;
}

void ReadCamera(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  BlobCameraRow& c = *static_cast<BlobCameraRow*>(row);
  if (r.Has("range")) c.range = r.Number("range", kPositiveLength);
  if (r.Has("fov_deg")) c.fov = ReadAperture(r, "fov_deg", 360);
  if (r.Has("vertical_fov_deg")) c.vertical_fov = ReadAperture(r, "vertical_fov_deg", 180);
  if (r.Has("occlusion")) c.occlusion = r.Bool("occlusion");
  static constexpr NumberRule kNoiseDeg{"an angle from 0 to 90 degrees", 0, 90};
  if (r.Has("angle_noise_deg")) c.angle_noise = r.Number("angle_noise_deg", kNoiseDeg) * kDeg;
  if (r.Has("distance_noise")) c.distance_noise = r.Number("distance_noise", kFraction);
  if (r.Has("failure_probability")) c.failure = r.Number("failure_probability", kFraction);
  if (r.Has("enabled")) c.enabled = r.Bool("enabled");
}

void ScaleLed(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  static_cast<LedRow*>(row)->radius *= s;
}

void ScaleCamera(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  BlobCameraRow& c = *static_cast<BlobCameraRow*>(row);
  c.range *= s;
  for (Blob& blob : c.blobs) blob.distance *= s;
}

// A copy sees afresh: the settings, no blobs.
void CopyCamera(const void* source, void* row) {
  BlobCameraRow& to = *static_cast<BlobCameraRow*>(row);
  to = *static_cast<const BlobCameraRow*>(source);
  to.blobs.clear();
}

// An LED's colour and switch change what other robots see.
void HashLeds(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<LedRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].color);
    h->AddValue(rows.rows[r].on);
  }
}

// The readings the scripts act on next.
void HashCameras(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<BlobCameraRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const BlobCameraRow& c = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(c.enabled);
    h->AddValue(c.blobs.size());
    for (const Blob& b : c.blobs) {
      h->AddValue(b.color);
      h->AddValue(b.distance);
      h->AddValue(b.bearing);
      h->AddValue(b.elevation);
      h->AddValue(b.led);
    }
  }
}

// Snapshots: an LED's colour and switch (what scripts and plugins change), a
// camera's switch and what it saw (what HashLeds and HashCameras add).
void SaveLeds(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const LedRow& led : scene.rows<LedRow>(type).rows) {
    out->Put(led.color);
    out->Put<uint8_t>(led.on);
  }
}
void LoadLeds(Scene* scene, ObjectType type, StateReader* in) {
  for (LedRow& led : scene->rows<LedRow>(type).rows) {
    led.color = in->Get<Vec3>();
    led.on = in->GetBool();
  }
}
static_assert(sizeof(Blob) == 56, "no padding: written as bytes");
void SaveCameras(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const BlobCameraRow& c : scene.rows<BlobCameraRow>(type).rows) {
    out->Put<uint8_t>(c.enabled);
    out->Put<uint64_t>(c.blobs.size());
    out->PutBytes(c.blobs.data(), c.blobs.size() * sizeof(Blob));
  }
}
void LoadCameras(Scene* scene, ObjectType type, StateReader* in) {
  for (BlobCameraRow& c : scene->rows<BlobCameraRow>(type).rows) {
    c.enabled = in->GetBool();
    c.blobs.resize(in->GetCount(sizeof(Blob)));
    in->GetBytes(c.blobs.data(), c.blobs.size() * sizeof(Blob));
  }
}

// Drawn as a light: glowing in its colour while on (and not black).
void LedVisual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const LedRow& led = scene.rows<LedRow>(type).rows[row];
  out->kind = VisualKind::kLight;
  out->size = {led.radius, 0, 0};
  out->color = led.color;
  out->on = led.on;
}

std::shared_ptr<const ObjectTypeDescriptor> LedType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = kLedTypeName;
  t->description = "a coloured LED (on/off, colour set by scripts) that blob cameras see";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<LedRow>>();
  };
  t->scale_row = ScaleLed;
  t->hash_rows = HashLeds;
  t->keys = kLedKeys;
  t->read = ReadLed;
  t->register_lua = RegisterBlobsApi;
  t->visual = LedVisual;
  t->save_rows = SaveLeds;
  t->load_rows = LoadLeds;
  return t;
}

std::shared_ptr<const ObjectTypeDescriptor> CameraType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = kBlobCameraTypeName;
  t->description =
      "sees the lit LEDs of other robots in range and field of view: colour, distance, bearing";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<BlobCameraRow>>();
  };
  t->copy_row = CopyCamera;
  t->scale_row = ScaleCamera;
  t->hash_rows = HashCameras;
  t->keys = kCameraKeys;
  t->read = ReadCamera;
  t->save_rows = SaveCameras;
  t->load_rows = LoadCameras;
  return t;
}

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"sensor", kModuleName, "1.0",
        "LEDs and blob cameras: LEDs in range and view, occlusion by ray tests (led, blob_camera "
        "types)"},
       PhaseBit(Phase::kSense),
       150,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<BlobCameraModule>(); }});
  registry->RegisterObjectType(LedType());
  registry->RegisterObjectType(CameraType());
  RegisterColorMetrics(registry);
}

}  // namespace swarmsim::blobs
