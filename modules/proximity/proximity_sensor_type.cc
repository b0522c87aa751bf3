// The proximity_sensor object type (rows: proximity_sensor.h): a ray along
// the sensor's +z axis, random rays in a cone, or a detection volume (cone,
// pyramid, cylinder, disc) that reports the nearest shape within its range
// (the backend, proximity.cc, senses it); its keys, reader, scaling and
// hash, and the lookups proximity_sensor.h declares.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/proximity/proximity_sensor.h"

namespace swarmsim {

namespace proximity {
// Its Lua API area (lua_api_proximity.cc).
void RegisterProximityApi(lua_State* L);
}  // namespace proximity

const char* ToString(ProximityVolume volume) {
  switch (volume) {
    case ProximityVolume::kRay: return "ray";
    case ProximityVolume::kRandomizedRay: return "randomized_ray";
    case ProximityVolume::kCone: return "cone";
    case ProximityVolume::kPyramid: return "pyramid";
    case ProximityVolume::kCylinder: return "cylinder";
    case ProximityVolume::kDisc: return "disc";
  }
  return "?";
}

namespace {

constexpr ObjectKey kKeys[] = {
    {"range", "0.1", "m, > 0: nothing farther from the sensor's origin is detected"},
    {"volume", "ray", "ray, randomized_ray, cone, pyramid, cylinder or disc"},
    {"angle_deg", "30", "half-angle: cone and randomized_ray (< 90), disc's half sector (<= 90)"},
    {"angle_x_deg", "30", "pyramid: half-angle in the sensor's xz plane (< 90)"},
    {"angle_y_deg", "30", "pyramid: half-angle in the sensor's yz plane (< 90)"},
    {"cylinder_radius", "0.05", "m, > 0: the cylinder volume's radius"},
    {"thickness", "0.01", "m, > 0: disc, along the sensor's z"},
    {"ray_count", "16", "randomized_ray: rays per step, 1..1024"},
    {"blind_zone", "0", "m, >= 0, < range: volumes start this far along their axis"},
    {"max_detection_angle_deg", "180",
     "a point whose normal is more than this from the direction back to the sensor is not "
     "detected (0 < angle <= 180; 180: no cut-off)"},
    {"detect_front", "true", "volumes: mesh faces seen from outside are detected"},
    {"detect_back", "true", "volumes: mesh faces seen from inside are detected"},
    {"detectable", "everything",
     "volumes and randomized_ray: only the shapes of this collection or object subtree (a path, "
     "':/parts' or '/walls')"},
    {"noise", "0", "m, >= 0: std dev of Gaussian noise on a detection's distance"},
    {"noise_uniform", "0", "m, >= 0: half width of uniform noise on a detection's distance"},
    {"failure_probability", "0", "0..1: chance that the sensor detects nothing in a step"},
    {"response", "none",
     "[[distance m, value], ...]: the raw value against distance (an IR sensor's curve), "
     "interpolated; nothing detected reads the last value; noise then perturbs the value"},
    {"response_incidence", "lambertian",
     "lambertian (the value above the far end times the cosine of the angle of incidence) or "
     "none"},
};

constexpr double kDeg = 3.141592653589793 / 180;

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<ProximitySensorData>>();
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  ProximitySensorData& p = *static_cast<ProximitySensorData*>(row);
  ProximitySensorSettings& settings = p.settings.Edit();  // this copy's own, scaled
  settings.range *= s;
  settings.radius *= s;
  settings.thickness *= s;
  settings.blind_zone *= s;
  for (auto& [distance, value] : settings.response) distance *= s;
  p.distance *= s;
  p.point = p.point * s;
}

// Ray sensors add what they always added (the golden hashes stay); volume
// sensors add their normal too, sensors with a response curve their value.
void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<ProximitySensorData>& sensors = scene.rows<ProximitySensorData>(type);
  for (size_t r = 0; r < sensors.rows.size(); ++r) {
    const ProximitySensorData& p = sensors.rows[r];
    h->AddValue(sensors.owners[r]);
    h->AddValue(p.detected);
    h->AddValue(p.distance);
    h->AddValue(p.p_SD());
    h->AddValue(p.detected_object);
    if (p.volume() != ProximityVolume::kRay) h->AddValue(p.normal);
    if (p.settings->has_response() && p.detected) h->AddValue(p.value);
  }
}

// Snapshots (framework/world_state.h): the readings.
void Save(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const ProximitySensorData& p : scene.rows<ProximitySensorData>(type).rows) {
    out->Put(p.distance);
    out->Put(p.detected_object);
    out->Put<uint8_t>(p.detected);
    out->Put(p.value);
    out->Put(p.point);
    out->Put(p.normal);
  }
}

void Load(Scene* scene, ObjectType type, StateReader* in) {
  for (ProximitySensorData& p : scene->rows<ProximitySensorData>(type).rows) {
    p.distance = in->Get<double>();
    p.detected_object = in->Get<ObjectId>();
    p.detected = in->GetBool();
    p.value = in->Get<float>();
    p.point = in->Get<Vec3>();
    p.normal = in->Get<Vec3>();
  }
}

// An angle in degrees, 0 < a < 90 (or <= `max_deg` if `max_inclusive`), in rad.
double ReadAngle(const ObjectReader& r, const char* key, double max_deg, bool max_inclusive,
                 double min_deg = 0, bool min_exclusive = true) {
  static constexpr NumberRule kAnyAngle{"an angle in degrees", -1e300, 1e300};
  const double a = r.Number(key, kAnyAngle);
  const bool low_ok = min_exclusive ? a > min_deg : a >= min_deg;
  const bool high_ok = max_inclusive ? a <= max_deg : a < max_deg;
  if (!(low_ok && high_ok)) {
    char message[200];
    std::snprintf(message, sizeof message, "'%s' must be an angle %s %g and %s %g degrees (got %g)",
                  key, min_exclusive ? "above" : "from", min_deg, max_inclusive ? "up to" : "below",
                  max_deg, a);
    r.Fail(key, message);
  }
  return a * kDeg;
}

// The detectable set's path matches objects.
void Check(const Scene& scene, ObjectId id, const void* row) {
  const ProximitySensorSettings& v = *static_cast<const ProximitySensorData*>(row)->settings;
  if (v.detectable.empty()) return;
  EntitySlots(scene, v.detectable, id,
              (v.detectable_where.empty() ? "" : v.detectable_where + ": ") + "proximity sensor " +
                  scene.PathOf(id) + " ('detectable')");
}

// `response: [[distance, value], ...]` (at least two pairs, distances from
// 0 and strictly increasing) and `response_incidence`. Without a `range`,
// the range is the table's last distance.
void ReadResponse(const ObjectReader& r, ProximitySensorSettings* p) {
  if (r.Has("response_incidence")) {
    if (!r.Has("response"))
      r.FailAtKey("response_incidence", "'response_incidence' needs a 'response' curve");
    p->response_lambertian = r.Choice("response_incidence", {"lambertian", "none"}) == "lambertian";
  }
  if (!r.Has("response")) return;
  static constexpr NumberRule kValue{"a number", -1e12, 1e12};
  const auto pairs = r.Elements("response", "[distance, value] pairs", "'response'", "pair");
  if (pairs.size() < 2 || pairs.size() > 1024)
    r.Fail("response", "'response' must list 2 to 1024 [distance, value] pairs");
  p->response.clear();
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::vector<double> pair = pairs[i]->Numbers("pair", 2, 2, kValue);
    if (pair[0] < 0 || pair[0] > kMaxLength)
      r.FailAtElement("response", i, "a response distance must be a non-negative number of m");
    if (i > 0 && !(pair[0] > p->response.back().first))
      r.FailAtElement("response", i,
                      "response distances must increase strictly (" + std::to_string(pair[0]) +
                          " m after " + std::to_string(p->response.back().first) + " m)");
    p->response.emplace_back(pair[0], pair[1]);
  }
  if (!r.Has("range")) p->range = p->response.back().first;
  if (!(p->range > 0)) r.Fail("response", "the last response distance must be above 0 m");
}

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  ProximitySensorSettings& p = static_cast<ProximitySensorData*>(row)->settings.Edit();
  if (r.Has("range")) p.range = r.Number("range", kPositiveLength);
  ReadNoise(r, "", kMaxLength, &p.noise);
  static const std::vector<std::string> kVolumes = {"ray",     "randomized_ray", "cone",
                                                    "pyramid", "cylinder",       "disc"};
  if (r.Has("volume")) {
    const std::string v = r.Choice("volume", kVolumes);
    for (size_t i = 0; i < kVolumes.size(); ++i)
      if (v == kVolumes[i]) p.volume = static_cast<ProximityVolume>(i);
  }
  using V = ProximityVolume;
  const V v = p.volume;
  const bool solid = v == V::kCone || v == V::kPyramid || v == V::kCylinder || v == V::kDisc;
  // Each key applies to some volumes: elsewhere it is an error.
  auto applies = [&](const char* key, bool ok, const char* where) {
    if (!r.Has(key)) return false;
    if (!ok) r.FailAtKey(key, std::string("'") + key + "' applies to " + where + " sensors only");
    return true;
  };
  if (applies("angle_deg", v == V::kCone || v == V::kRandomizedRay || v == V::kDisc,
              "cone, randomized_ray and disc"))
    p.angle = v == V::kRandomizedRay ? ReadAngle(r, "angle_deg", 90, false, 0, false)
                                     : ReadAngle(r, "angle_deg", 90, v == V::kDisc);
  if (applies("angle_x_deg", v == V::kPyramid, "pyramid"))
    p.angle = ReadAngle(r, "angle_x_deg", 90, false);
  if (applies("angle_y_deg", v == V::kPyramid, "pyramid"))
    p.angle_y = ReadAngle(r, "angle_y_deg", 90, false);
  if (applies("cylinder_radius", v == V::kCylinder, "cylinder"))
    p.radius = r.Number("cylinder_radius", kPositiveLength);
  if (applies("thickness", v == V::kDisc, "disc"))
    p.thickness = r.Number("thickness", kPositiveLength);
  if (applies("ray_count", v == V::kRandomizedRay, "randomized_ray"))
    p.ray_count = static_cast<uint16_t>(r.Integer("ray_count", 1, 1024));
  if (applies("blind_zone", solid, "cone, pyramid, cylinder and disc")) {
    p.blind_zone = r.Number("blind_zone", kNonNegativeLength);
    if (!(p.blind_zone < p.range))
      r.Fail("blind_zone", "'blind_zone' (" + std::to_string(p.blind_zone) +
                               " m) must be less than the range (" + std::to_string(p.range) +
                               " m)");
  }
  if (r.Has("max_detection_angle_deg"))
    p.max_detection_angle = ReadAngle(r, "max_detection_angle_deg", 180, true);
  if (applies("detect_front", solid, "cone, pyramid, cylinder and disc"))
    p.detect_front = r.Bool("detect_front");
  if (applies("detect_back", solid, "cone, pyramid, cylinder and disc"))
    p.detect_back = r.Bool("detect_back");
  if (applies("detectable", v != V::kRay, "volume and randomized_ray")) {
    p.detectable = r.String("detectable");
    p.detectable_where = r.Where("detectable");
    const std::string& path = p.detectable;
    if (path.empty() || (path[0] != '/' && path[0] != ':' && path[0] != '.'))
      r.Fail("detectable", "'" + path +
                               "' is not an object path: start with '/' (absolute), ':' (this "
                               "model) or './' (below the sensor)");
  }
  ReadResponse(r, &p);
  if (!p.detect_front && !p.detect_back)
    r.FailAtKey(r.Has("detect_back") ? "detect_back" : "detect_front",
                "detect_front and detect_back are both false: the sensor would detect nothing");
}

// Drawn as its ray (a marker): its range long, to the detected point, red
// while it detects something, else blue.
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const ProximitySensorData& p = scene.rows<ProximitySensorData>(type).rows[row];
  out->kind = VisualKind::kRay;
  out->size = {p.range(), 0, 0};
  out->hit = p.detected ? p.distance : -1;
  out->color = p.detected ? Vec3{1, 0.2, 0.2} : Vec3{0.3, 0.8, 1};
}

constinit const ObjectTypeDescriptor kProximitySensorType{
    .name = proximity::kSensorTypeName,
    .description =
        "a ray along its +z axis, random rays in a cone, or a detection volume (cone, pyramid, "
        "cylinder, disc): the nearest shape within its range",
    .make_rows = MakeRows,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .check = Check,
    .register_lua = proximity::RegisterProximityApi,
    .visual = Visual,
    // Where it was when it was a built-in type: hashes and type lists stay.
    .listed_after = "joint",
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace

namespace proximity {

const ObjectTypeDescriptor& SensorTypeDescriptor() { return kProximitySensorType; }

ObjectType SensorType(Scene* scene) {
  ObjectType type;
  if (FindSensorType(*scene, &type)) return type;
  return scene->RegisterType(kProximitySensorType);
}

ObjectId AddSensor(Scene* scene, std::string name, ObjectId parent, const Pose& X_PO,
                   const ProximitySensorData& sensor) {
  return scene->AddObject(SensorType(scene), std::move(name), parent, X_PO, &sensor);
}

const ProximitySensorData& Sensor(const Scene& scene, ObjectId id) {
  const uint32_t slot = scene.SlotOf(id, "proximity sensor");
  if (!IsSensorAt(scene, slot))
    throw Error("object '" + scene.name_at(slot) + "' is a " +
                scene.type_name(scene.type_at(slot)) + ", not a " + kSensorTypeName);
  return scene.rows<ProximitySensorData>(scene.type_at(slot)).rows[scene.row_at(slot)];
}

ProximitySensorData& MutableSensor(Scene* scene, ObjectId id) {
  return const_cast<ProximitySensorData&>(Sensor(*scene, id));
}

Rows<ProximitySensorData>& MutableSensors(Scene* scene) {
  return scene->rows<ProximitySensorData>(SensorType(scene));
}

}  // namespace proximity
}  // namespace swarmsim
