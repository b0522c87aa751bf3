// The `ir_transceiver` object type (ir_messaging.h): its keys, reader,
// copy, scale, hash and visual, and the module's registration.
#include <memory>
#include <string>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/state_hash.h"
#include "framework/world_state.h"
#include "modules/ir_messaging/ir_messaging.h"
#include "modules/ir_messaging/module.h"

namespace swarmsim::ir_messaging {

namespace {

// The defaults are the Kilobot's; worlds/README.md cites each source.
constexpr ObjectKey kKeys[] = {
    {"range", "0.1",
     "m, > 0: the transceiver hears messages sent from within it, origin to origin (Kilobot "
     "0.1)"},
    {"payload_size", "12", "bytes a message carries at most, 1..255 (Kilobot 12)"},
    {"packet_time", "0.004035",
     "s, > 0: how long a message is on the air (Kilobot: 12 bytes x 10 bits x 33.6 us)"},
    {"distance_noise", "0.002",
     "m, >= 0: std dev of Gaussian noise on the receiver's distance estimate"},
    {"loss_probability", "0", "0..1: each message heard is lost with this probability"},
    {"failure_probability", "0", "0..1: the transceiver hears nothing at a step"},
    {"carrier_sense", "true",
     "a sender that hears a message on the air at its start time defers (sends nothing)"},
    {"collisions", "true",
     "messages overlapping in time are both lost at a receiver that hears both"},
};

void Read(const ObjectTypeDescriptor&, const ObjectReader& r, void* row) {
  IrTransceiverRow& ir = *static_cast<IrTransceiverRow*>(row);
  IrSettings& s = ir.settings.Edit();
  if (r.Has("range")) s.range = r.Number("range", kPositiveLength);
  if (r.Has("payload_size"))
    s.payload_size = static_cast<uint32_t>(r.Integer("payload_size", 1, kMaxPayloadSize));
  static constexpr NumberRule kSeconds{"a positive number of seconds (at most 1000)", 0, 1000,
                                       true};
  if (r.Has("packet_time")) s.packet_time = r.Number("packet_time", kSeconds);
  static constexpr NumberRule kNoise{"a non-negative number of metres (at most 1000)", 0, 1000};
  if (r.Has("distance_noise")) s.distance_noise = r.Number("distance_noise", kNoise);
  if (r.Has("loss_probability")) s.loss_probability = r.Number("loss_probability", kFraction);
  if (r.Has("failure_probability"))
    s.failure_probability = r.Number("failure_probability", kFraction);
  if (r.Has("carrier_sense")) s.carrier_sense = r.Bool("carrier_sense");
  if (r.Has("collisions")) s.collisions = r.Bool("collisions");
}

// A copy shares the settings and starts with nothing queued or heard.
void Copy(const void* source, void* row) {
  static_cast<IrTransceiverRow*>(row)->settings =
      static_cast<const IrTransceiverRow*>(source)->settings;
}

void Scale(const ObjectTypeDescriptor&, void* row, double s, ScaleContext*) {
  IrTransceiverRow& ir = *static_cast<IrTransceiverRow*>(row);
  IrSettings& settings = ir.settings.Edit();
  settings.range *= s;
  settings.distance_noise *= s;
  for (IrReceived& r : ir.inbox) r.distance *= s;
}

// What each transceiver has queued, whether it sent, and what it heard.
void Hash(const Scene& scene, ObjectType type, StateHasher* h) {
  const Rows<IrTransceiverRow>& rows = scene.rows<IrTransceiverRow>(type);
  for (size_t r = 0; r < rows.size(); ++r) {
    const IrTransceiverRow& ir = rows.rows[r];
    h->AddValue(rows.owners[r]);
    h->AddValue(ir.queued);
    if (ir.queued) {
      h->AddValue(ir.outgoing.size());
      if (!ir.outgoing.empty()) h->Add(ir.outgoing.data(), ir.outgoing.size());
    }
    h->AddValue(ir.sent);
    h->AddValue(ir.inbox.size());
    for (const IrReceived& m : ir.inbox) {
      h->AddValue(m.distance);
      h->AddValue(m.sender);
      h->AddValue(m.data_size);
    }
    if (!ir.received.empty()) h->Add(ir.received.data(), ir.received.size());
  }
}

// Snapshots: what each transceiver has queued, whether it sent, and what
// it heard (with the payload offsets the readers use), as Hash adds them.
static_assert(sizeof(IrReceived) == 24, "no padding: written as bytes");
void Save(const Scene& scene, ObjectType type, StateWriter* out) {
  for (const IrTransceiverRow& ir : scene.rows<IrTransceiverRow>(type).rows) {
    out->Put<uint8_t>(ir.queued);
    out->Put<uint8_t>(ir.sent);
    out->Put<uint64_t>(ir.outgoing.size());
    out->PutBytes(ir.outgoing.data(), ir.outgoing.size());
    out->Put<uint64_t>(ir.inbox.size());
    out->PutBytes(ir.inbox.data(), ir.inbox.size() * sizeof(IrReceived));
    out->Put<uint64_t>(ir.received.size());
    out->PutBytes(ir.received.data(), ir.received.size());
  }
}

void Load(Scene* scene, ObjectType type, StateReader* in) {
  for (IrTransceiverRow& ir : scene->rows<IrTransceiverRow>(type).rows) {
    ir.queued = in->GetBool();
    ir.sent = in->GetBool();
    ir.outgoing.resize(in->GetCount(1));
    in->GetBytes(ir.outgoing.data(), ir.outgoing.size());
    if (ir.outgoing.size() > ir.settings->payload_size)
      in->Fail("an IR message of " + std::to_string(ir.outgoing.size()) +
               " bytes, more than its transceiver's payload_size");
    ir.inbox.resize(in->GetCount(sizeof(IrReceived)));
    in->GetBytes(ir.inbox.data(), ir.inbox.size() * sizeof(IrReceived));
    ir.received.resize(in->GetCount(1));
    in->GetBytes(ir.received.data(), ir.received.size());
    for (const IrReceived& m : ir.inbox)
      if (m.data_offset > ir.received.size() || m.data_size > ir.received.size() - m.data_offset)
        in->Fail("an IR message's bytes lie outside the bytes received");
  }
}

// Drawn as a small disc (1.5 cm across, 2 mm high): red when its message
// went out, green when it heard one, grey otherwise.
void Visual(const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
  const IrTransceiverRow& ir = scene.rows<IrTransceiverRow>(type).rows[row];
  out->kind = VisualKind::kCylinder;
  out->size = {0.0075, 0, 0.002};
  out->color = ir.sent            ? Vec3{0.9, 0.2, 0.2}
               : ir.inbox.empty() ? Vec3{0.5, 0.5, 0.5}
                                  : Vec3{0.2, 0.9, 0.4};
}

// The transceivers it heard in the last sense phase (the recorder's links).
void Links(const Scene& scene, ObjectType type, uint32_t row, std::vector<ObjectId>* out) {
  for (const IrReceived& m : scene.rows<IrTransceiverRow>(type).rows[row].inbox)
    out->push_back(m.sender);
}

std::unique_ptr<RowTable> MakeRows(const ObjectTypeDescriptor&) {
  return std::make_unique<Rows<IrTransceiverRow>>();
}

constinit const ObjectTypeDescriptor kIrTransceiverType{
    .name = kTypeName,
    .description =
        "an IR transceiver (the Kilobot's): short messages through the floor, with the "
        "receiver's distance estimate, carrier sense and collisions",
    .make_rows = MakeRows,
    .copy_row = Copy,
    .scale_row = Scale,
    .hash_rows = Hash,
    .keys = kKeys,
    .read = Read,
    .register_lua = RegisterIrMessagingApi,
    .visual = Visual,
    .links = Links,
    .save_rows = Save,
    .load_rows = Load,
};

}  // namespace

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"sensor", kModuleName, "1.0",
        "IR transceivers: Kilobot-style messages within range, carrier sense, collisions, loss, "
        "distance estimates (ir_transceiver type)"},
       PhaseBit(Phase::kSense),
       170,
       /*every_world=*/true,
       [](World*, const void*) { return std::make_unique<IrMessagingModule>(); },
       nullptr});
  registry->RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kIrTransceiverType));
}

}  // namespace swarmsim::ir_messaging
