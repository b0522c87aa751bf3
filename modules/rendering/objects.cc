// The `camera`, `vision_sensor` and `light` object types (objects.h) and the
// module's registration.
#include "modules/rendering/objects.h"

#include <cmath>
#include <memory>
#include <string>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "modules/rendering/module.h"
#include "modules/rendering/vision_sensor.h"

namespace swarmsim::rendering {

// The Lua area of the three types (lua_api_rendering.cc).
void RegisterRenderingApi(lua_State* L);

namespace {

constexpr double kDeg = M_PI / 180;

constexpr ObjectKey kCameraKeys[] = {
    {"resolution", "[640, 480]", "[width, height] pixels, each 1..8192"},
    {"projection", "perspective", "perspective or orthographic"},
    {"fov_deg", "60", "perspective: horizontal field of view, 0 < fov < 180"},
    {"ortho_width", "1", "m, > 0, orthographic: the width the image spans"},
    {"near", "0.05", "m, > 0: the near clipping plane"},
    {"far", "50", "m, > near: the far clipping plane"},
};

constexpr ObjectKey kVisionSensorKeys[] = {
    {"resolution", "[64, 48]", "[width, height] pixels, each 1..8192"},
    {"projection", "perspective", "perspective or orthographic"},
    {"fov_deg", "60", "perspective: horizontal field of view, 0 < fov < 180"},
    {"ortho_width", "1", "m, > 0, orthographic: the width the image spans"},
    {"near", "0.01", "m, > 0: the near clipping plane"},
    {"far", "10", "m, > near: the far clipping plane (nothing farther is seen)"},
    {"depth", "true", "also keep the depth image (sim.getVisionSensorDepth)"},
    {"rate", "every step", "Hz, > 0: images per simulated second (rounded to whole steps)"},
    {"detectable", "everything",
     "only the shapes (and LEDs) of this collection or object subtree are seen (a path)"},
    {"background", "[0, 0, 0]", "RGB, each 0..1: where nothing is seen"},
    {"floor", "true", "the floor (and the paint layer on it) is seen"},
    {"filters", "none",
     "a filter chain run on each image: a list of elements (see vision sensor filters)"},
};

constexpr ObjectKey kLightKeys[] = {
    {"kind", "directional", "directional (along its +x), point, or spot (a cone about its +x)"},
    {"color", "[1, 1, 1]", "RGB, each 0..1"},
    {"on", "true", "lit from the first step"},
    {"cutoff_deg", "30", "spot: half-angle of the cone, 0 < angle <= 90"},
    {"exponent", "2", "spot: intensity falls off as cos(angle)^exponent, 0..128"},
    {"range", "0",
     "m, >= 0, point and spot: the intensity halves at this distance (0: no fall-off)"},
};

void ReadLens(const ObjectReader& r, Lens* lens) {
  if (r.Has("resolution")) {
    const std::vector<double> v = r.Numbers("resolution", 2, 2, kPositive);
    for (double x : v)
      if (x != std::floor(x) || x < 1 || x > 8192)
        r.Fail("resolution",
               "each side of 'resolution' is a whole number of pixels from 1 to 8192");
    lens->width = static_cast<int>(v[0]);
    lens->height = static_cast<int>(v[1]);
  }
  if (r.Has("projection"))
    lens->orthographic = r.Choice("projection", {"perspective", "orthographic"}) == "orthographic";
  if (r.Has("fov_deg")) {
    const double fov = r.Number("fov_deg", kAngleDeg);
    if (!(fov > 0 && fov < 180)) r.Fail("fov_deg", "'fov_deg' is more than 0 and less than 180");
    lens->fov = fov * kDeg;
  }
  if (r.Has("ortho_width")) lens->ortho_width = r.Number("ortho_width", kPositiveLength);
  if (r.Has("near")) lens->near = r.Number("near", kPositiveLength);
  if (r.Has("far")) lens->far = r.Number("far", kPositiveLength);
  if (!(lens->far > lens->near))
    r.Fail(r.Has("far") ? "far" : "near", "'far' (" + std::to_string(lens->far) +
                                              ") must be more than 'near' (" +
                                              std::to_string(lens->near) + ")");
}

void ReadCamera(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  ReadLens(r, &static_cast<CameraRow*>(row)->lens);
}

void ReadVisionSensor(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  VisionSensorRow& v = *static_cast<VisionSensorRow*>(row);
  ReadLens(r, &v.lens);
  if (r.Has("depth")) v.depth = r.Bool("depth");
  if (r.Has("rate")) v.rate = r.Number("rate", kPositive);
  if (r.Has("detectable")) {
    v.detectable = r.String("detectable");
    v.where = r.Where("detectable");
    const EntitySpec e = ParseEntity(v.detectable);
    if (e.kind != EntitySpec::kPath || e.path.empty())
      r.Fail("detectable", "'detectable' is an object path or a collection ('/walls', ':/parts')");
  }
  if (r.Has("background")) v.background = r.Vector3("background", kFraction);
  if (r.Has("floor")) v.floor = r.Bool("floor");
  if (r.Has("filters")) {
    v.filters = filters::ParseFilterChain(r, "filters", r.registry());
    if (v.filters.needs_depth()) v.depth = true;
  }
}

void ReadLight(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  LightRow& l = *static_cast<LightRow*>(row);
  if (r.Has("kind")) {
    const std::string kind = r.Choice("kind", {"directional", "point", "spot"});
    l.kind = kind == "point"  ? LightSource::kPoint
             : kind == "spot" ? LightSource::kSpot
                              : LightSource::kDirectional;
  }
  if (r.Has("color")) l.color = r.Vector3("color", kFraction);
  if (r.Has("on")) l.on = r.Bool("on");
  if (r.Has("cutoff_deg")) {
    const double a = r.Number("cutoff_deg", kAngleDeg);
    if (!(a > 0 && a <= 90)) r.Fail("cutoff_deg", "'cutoff_deg' is more than 0 and at most 90");
    l.cutoff = a * kDeg;
  }
  if (r.Has("exponent")) {
    l.exponent = r.Number("exponent", kNonNegative);
    if (l.exponent > 128) r.Fail("exponent", "'exponent' is at most 128");
  }
  if (r.Has("range")) l.range = r.Number("range", kNonNegativeLength);
}

void ScaleLens(Lens* lens, double s) {
  lens->ortho_width *= s;
  lens->near *= s;
  lens->far *= s;
}

// A copy renders afresh.
void CopyVisionSensor(const void* source, void* row) {
  const VisionSensorRow& from = *static_cast<const VisionSensorRow*>(source);
  VisionSensorRow& to = *static_cast<VisionSensorRow*>(row);
  to.lens = from.lens;
  to.depth = from.depth;
  to.rate = from.rate;
  to.detectable = from.detectable;
  to.where = from.where;
  to.background = from.background;
  to.floor = from.floor;
  to.filters = from.filters;
}

void CheckVisionSensor(const Scene& scene, ObjectId id, const void* row) {
  const VisionSensorRow& v = *static_cast<const VisionSensorRow*>(row);
  if (v.detectable.empty()) return;
  EntitySlots(scene, ParseEntity(v.detectable).path, id,
              (v.where.empty() ? "" : v.where + ": ") + "vision sensor " + scene.PathOf(id) +
                  " ('detectable')");
}

// Lights change what vision sensors see, so what scripts set is hashed.
void HashLights(const Scene& scene, ObjectType type, StateHasher* h) {
  const auto& rows = static_cast<const Rows<LightRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    h->AddValue(rows.owners[r]);
    h->AddValue(rows.rows[r].on);
    h->AddValue(rows.rows[r].color);
  }
}

std::shared_ptr<const ObjectTypeDescriptor> CameraType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "camera";
  t->description = "a viewpoint for snapshots and video (--camera NAME), looking along its +x";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<CameraRow>>();
  };
  t->scale_row = [](const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
    ScaleLens(&static_cast<CameraRow*>(row)->lens, s);
  };
  t->keys = kCameraKeys;
  t->read = ReadCamera;
  return t;
}

std::shared_ptr<const ObjectTypeDescriptor> VisionSensorType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "vision_sensor";
  t->description = "a rendering sensor: RGB and depth images looking along its +x, each sense step";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<VisionSensorRow>>();
  };
  t->copy_row = CopyVisionSensor;
  t->scale_row = [](const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
    ScaleLens(&static_cast<VisionSensorRow*>(row)->lens, s);
  };
  t->keys = kVisionSensorKeys;
  t->read = ReadVisionSensor;
  t->check = CheckVisionSensor;
  t->register_lua = RegisterRenderingApi;
  return t;
}

std::shared_ptr<const ObjectTypeDescriptor> LightType() {
  auto t = std::make_shared<ObjectTypeDescriptor>();
  t->name = "light";
  t->description = "a directional, point or spot light with a colour, on or off";
  t->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<LightRow>>();
  };
  t->scale_row = [](const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
    static_cast<LightRow*>(row)->range *= s;
  };
  t->hash_rows = HashLights;
  t->keys = kLightKeys;
  t->read = ReadLight;
  t->register_lua = RegisterRenderingApi;
  return t;
}

}  // namespace

filters::CameraModel CameraModelOf(const Lens& lens) {
  filters::CameraModel camera;
  camera.perspective = !lens.orthographic;
  // The chain measures angles and sizes along the image's larger side.
  const double ratio = static_cast<double>(lens.height) / lens.width;
  camera.fov = lens.width >= lens.height ? lens.fov : 2 * std::atan(std::tan(lens.fov / 2) * ratio);
  camera.ortho_size = lens.width >= lens.height ? lens.ortho_width : lens.ortho_width * ratio;
  camera.near = lens.near;
  camera.far = lens.far;
  return camera;
}

void CollectLights(const Scene& scene, std::vector<LightSource>* lights, bool* any) {
  lights->clear();
  *any = false;
  ObjectType type;
  if (!scene.FindType("light", &type)) return;
  const auto& rows = static_cast<const Rows<LightRow>&>(*scene.rows(type));
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint32_t slot = rows.owners[r];
    if (!scene.alive_at(slot)) continue;
    *any = true;
    const LightRow& l = rows.rows[r];
    if (!l.on) continue;
    const Pose& X = scene.world_pose_at(slot);
    LightSource s;
    s.kind = l.kind;
    s.position = X.p;
    s.direction = X.q.Rotate({1, 0, 0});
    s.color = l.color;
    s.cutoff = l.cutoff;
    s.exponent = l.exponent;
    if (l.range > 0) s.attenuation[1] = 1 / l.range;
    lights->push_back(s);
  }
}

bool ReadVisionSensor(const Scene& scene, uint32_t slot, VisionReading* out) {
  ObjectType type;
  if (!scene.FindType("vision_sensor", &type) || scene.type_at(slot) != type) return false;
  const VisionSensorRow& s = scene.rows<VisionSensorRow>(type).rows[scene.row_at(slot)];
  *out = {};
  out->width = s.lens.width;
  out->height = s.lens.height;
  out->depth = s.depth;
  out->rendered_step = s.rendered_step;
  if (s.rendered_step >= 0) {
    out->image = &s.image;
    if (!s.filters.empty()) out->filtered = &s.output.image;
  }
  return true;
}

void RegisterObjects(ModuleRegistry* registry) {
  registry->RegisterModule(RenderingModuleDescriptor());
  registry->RegisterObjectType(CameraType());
  registry->RegisterObjectType(VisionSensorType());
  registry->RegisterObjectType(LightType());
}

}  // namespace swarmsim::rendering
