// The `range_and_bearing` object type (range_and_bearing.h): its keys,
// reader, copy, scale, hash and visual, and the module's registration.
#include <cstdio>
#include <memory>
#include <string>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/range_and_bearing/module.h"
#include "modules/range_and_bearing/range_and_bearing.h"

namespace swarmsim::range_and_bearing {

namespace {

constexpr double kDeg = 3.141592653589793 / 180;

constexpr ObjectKey kKeys[] = {
    {"range", "3",
     "m, > 0: the board hears the boards of other robots within it (foot-bot 3, e-puck 0.8)"},
    {"payload_size", "10", "bytes sent every step, 1..1024 (foot-bot 10, e-puck 4)"},
    {"loss_probability", "0",
     "0..1: every message is lost with this probability (plus loss_at_range's term)"},
    {"loss_at_range", "0",
     "0..1: added to the loss probability times (distance / range)^2: "
     "p = min(1, loss_probability + loss_at_range (d / range)^2)"},
    {"range_noise", "0", "m, >= 0: std dev of Gaussian noise on each reading's range"},
    {"range_noise_uniform", "0", "m, >= 0: half width of uniform noise on each reading's range"},
    {"bearing_noise_deg", "0",
     "std dev of Gaussian noise on bearing and elevation, 0..180 degrees"},
    {"bearing_noise_uniform_deg", "0",
     "half width of uniform noise on bearing and elevation, 0..180 degrees"},
    {"failure_probability", "0", "0..1: the board hears nothing at a step"},
    {"capacity", "unlimited", "readings kept per step at most, 1..1000000"},
    {"capacity_order", "nearest",
     "which readings the capacity keeps: nearest (the nearest senders) or random"},
    {"occlusion", "true", "static shapes and the environment map between two boards block"},
    {"robot_occlusion", "false", "other robots' shapes between two boards block too"},
};

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  RangeAndBearingRow& rab = *static_cast<RangeAndBearingRow*>(row);
  RangeAndBearingSettings& s = rab.settings.Edit();
  if (r.Has("range")) s.range = r.Number("range", kPositiveLength);
  if (r.Has("payload_size"))
    s.payload_size = static_cast<uint32_t>(r.Integer("payload_size", 1, kMaxPayloadSize));
  if (r.Has("loss_probability")) s.loss_probability = r.Number("loss_probability", kFraction);
  if (r.Has("loss_at_range")) s.loss_at_range = r.Number("loss_at_range", kFraction);
  // range_noise, range_noise_uniform (framework/sensor_noise.h's keys, in m).
  ReadNoise(r, "range_", kMaxLength, &s.range_noise);
  // The bearing's in degrees, as every angle of a world file.
  static constexpr NumberRule kNoiseDeg{"an angle from 0 to 180 degrees", 0, 180};
  if (r.Has("bearing_noise_deg"))
    s.bearing_noise.gaussian = r.Number("bearing_noise_deg", kNoiseDeg) * kDeg;
  if (r.Has("bearing_noise_uniform_deg"))
    s.bearing_noise.uniform = r.Number("bearing_noise_uniform_deg", kNoiseDeg) * kDeg;
  // failure_probability (sensor_noise.h's key): kept with the range's noise.
  if (r.Has("failure_probability"))
    s.range_noise.failure = r.Number("failure_probability", kFraction);
  if (r.Has("capacity")) s.capacity = static_cast<uint32_t>(r.Integer("capacity", 1, 1000000));
  if (r.Has("capacity_order"))
    s.capacity_order = r.Choice("capacity_order", {"nearest", "random"}) == "random"
                           ? CapacityOrder::kRandom
                           : CapacityOrder::kNearest;
  if (r.Has("occlusion")) s.occlusion = r.Bool("occlusion");
  if (r.Has("robot_occlusion")) s.robot_occlusion = r.Bool("robot_occlusion");
}

// A copy sends what its original sends and hears afresh.
void Copy(const void* source, void* row) {
  const RangeAndBearingRow& from = *static_cast<const RangeAndBearingRow*>(source);
  RangeAndBearingRow& to = *static_cast<RangeAndBearingRow*>(row);
  to.settings = from.settings;
  to.data = from.data;
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  RangeAndBearingRow& rab = *static_cast<RangeAndBearingRow*>(row);
  RangeAndBearingSettings& settings = rab.settings.Edit();
  settings.range *= s;
  settings.range_noise.gaussian *= s;
  settings.range_noise.uniform *= s;
  for (RangeAndBearingReading& reading : rab.readings) reading.range *= s;
}

// What each board sends and what it heard (what the scripts read next).
void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<RangeAndBearingRow>& rows = scene.rows<RangeAndBearingRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    const RangeAndBearingRow& rab = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(rab.data.size());
    if (!rab.data.empty()) h->Add(rab.data.data(), rab.data.size());
    h->AddValue(rab.readings.size());
    for (const RangeAndBearingReading& reading : rab.readings) {
      h->AddValue(reading.range);
      h->AddValue(reading.bearing);
      h->AddValue(reading.elevation);
      h->AddValue(reading.sender);
    }
    if (!rab.received.empty()) h->Add(rab.received.data(), rab.received.size());
  }
}

// Snapshots: what each board sends and what it heard, as Hash adds them
// (the readings' payload offsets too, which the Lua and Python readers use).
static_assert(sizeof(RangeAndBearingReading) == 40, "no padding: written as bytes");
void Save(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const RangeAndBearingRow& rab : scene.rows<RangeAndBearingRow>(type).rows) {
    out->Put<uint64_t>(rab.data.size());
    out->PutBytes(rab.data.data(), rab.data.size());
    out->Put<uint64_t>(rab.readings.size());
    out->PutBytes(rab.readings.data(), rab.readings.size() * sizeof(RangeAndBearingReading));
    out->Put<uint64_t>(rab.received.size());
    out->PutBytes(rab.received.data(), rab.received.size());
  }
}

void Load(Scene* scene, ObjectType type, StateReader* in) {
  for (RangeAndBearingRow& rab : scene->rows<RangeAndBearingRow>(type).rows) {
    rab.data.resize(in->GetCount(1));
    in->GetBytes(rab.data.data(), rab.data.size());
    if (rab.data.size() > rab.settings->payload_size)
      in->Fail("a range-and-bearing board sends " + std::to_string(rab.data.size()) +
               " bytes, more than its payload_size");
    rab.readings.resize(in->GetCount(sizeof(RangeAndBearingReading)));
    in->GetBytes(rab.readings.data(), rab.readings.size() * sizeof(RangeAndBearingReading));
    rab.received.resize(in->GetCount(1));
    in->GetBytes(rab.received.data(), rab.received.size());
    for (const RangeAndBearingReading& r : rab.readings)
      if (r.data_offset > rab.received.size() || r.data_size > rab.received.size() - r.data_offset)
        in->Fail("a range-and-bearing reading's payload lies outside the bytes received");
  }
}

// Drawn as a small puck (2 cm across, 1 cm high): green while it hears
// another board, grey otherwise.
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const RangeAndBearingRow& rab = scene.rows<RangeAndBearingRow>(type).rows[row];
  out->kind = VisualKind::kCylinder;
  out->size = {0.02, 0, 0.01};
  out->color = rab.readings.empty() ? Vec3{0.5, 0.5, 0.5} : Vec3{0.2, 0.9, 0.4};
}

// The boards it heard in the last sense phase (the recorder's links).
void Links(const Scene& scene, ObjectType type, uint32_t row, std::vector<ObjectId>* out) {
  for (const RangeAndBearingReading& r : scene.rows<RangeAndBearingRow>(type).rows[row].readings)
    out->push_back(r.sender);
}

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<RangeAndBearingRow>>();
}

constinit const ObjectTypeDescriptor kRangeAndBearingType{
    .name = kTypeName,
    .description =
        "a range-and-bearing board: sends a few bytes every step; hears other robots' with their "
        "distance and bearing",
    .make_rows = MakeRows,
    .copy_row = Copy,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterRangeAndBearingApi,
    .visual = Visual,
    .links = Links,
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"sensor", kModuleName, "1.0",
        "range-and-bearing boards: payloads with range and bearing, occlusion, loss, noise, "
        "capacity (range_and_bearing type)"},
       PhaseBit(Phase::kSense),
       160,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<RangeAndBearingModule>(); },
       nullptr});
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kRangeAndBearingType));
}

}  // namespace swarmsim::range_and_bearing
