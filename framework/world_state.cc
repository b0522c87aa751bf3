// World snapshots: World::SaveState and World::RestoreState (the design is
// in world_state.h), and the StateReader's checks.
#include "framework/world_state.h"

#include <xxhash.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/plugin_controllers.h"
#include "framework/state_hash.h"
#include "framework/world.h"

namespace swarmsim {

namespace {

// The bytes: magic, format version, payload size, payload checksum, payload.
constexpr char kMagic[16] = "swarmsim-state";  // 14 characters and two zeros
constexpr uint32_t kVersion = 2;  // 2: the swarm devices' rows, parameters set after load
constexpr size_t kHeaderBytes = sizeof kMagic + sizeof(uint32_t) + 2 * sizeof(uint64_t);

uint64_t Checksum(std::string_view payload) { return XXH3_64bits(payload.data(), payload.size()); }

// The world file's content (empty: a world built in code, or a file no
// longer readable).
uint64_t FileHash(const std::string& file) {
  if (file.empty()) return 0;
  std::ifstream in(file, std::ios::binary);
  if (!in) return 0;
  const std::string content{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return XXH3_64bits(content.data(), content.size());
}

}  // namespace

// --- StateReader ------------------------------------------------------------------------------

void StateReader::Fail(const std::string& message) const {
  throw Error("snapshot: " + message + " (the snapshot is corrupt or of another version)");
}

void StateReader::GetBytes(void* out, size_t size) {
  if (size > remaining())
    Fail("truncated: " + std::to_string(size) + " more bytes needed at offset " +
         std::to_string(offset_) + ", " + std::to_string(remaining()) + " left");
  if (size == 0) return;  // (an empty vector's data() may be null: no memcpy)
  std::memcpy(out, bytes_.data() + offset_, size);
  offset_ += size;
}

bool StateReader::GetBool() {
  const auto value = Get<uint8_t>();
  if (value > 1) Fail("a flag reads " + std::to_string(value));
  return value == 1;
}

uint64_t StateReader::GetCount(size_t item_size) {
  const auto count = Get<uint64_t>();
  if (item_size > 0 && count > remaining() / item_size)
    Fail("a count of " + std::to_string(count) + " items is more than the bytes left hold");
  return count;
}

std::string StateReader::GetString() {
  const uint64_t size = GetCount(1);
  std::string text(bytes_.substr(offset_, size));
  offset_ += size;
  return text;
}

void StateReader::Expect(uint64_t value, uint64_t expected, std::string_view what) const {
  if (value != expected)
    Fail(std::string(what) + " is " + std::to_string(value) + ", this world has " +
         std::to_string(expected));
}

// --- World
// ----------------------------------------------------------------------------------------

std::string World::SnapshotRefusal() const {
  const std::string why =
      ", whose state cannot be saved; drive the robots from Python "
      "(python_controller or World(controllers=...)) instead";
  if (settings_.main_script)
    return "the world runs the main script '" + settings_.main_script->path + "'" + why;
  for (uint32_t s = 0; s < scene_.slot_count(); ++s) {
    if (!scene_.alive_at(s)) continue;
    const ScriptAttachment* script = scene_.script_at(s);
    if (script == nullptr) continue;
    const int robot = scene_.instance_of_at(s);
    const std::string who = robot >= 0 ? "robot '" + scene_.instance(robot).name + "'"
                                       : "object '" + scene_.PathOf(scene_.IdAt(s)) + "'";
    return who + " runs Lua script '" + script->source->path + "'" + why;
  }
  if (controllers_)
    for (int r = 0; r < robot_count(); ++r)
      if (const PluginControllerType* type = controllers_->type_of(r); type != nullptr)
        return "robot '" + scene_.instance(r).name + "' runs the native controller '" + type->name +
               "' (" + type->plugin +
               "), whose memory cannot be saved; drive the robots from Python "
               "(python_controller or World(controllers=...)) to snapshot the world";
  for (const auto& callbacks : phase_callbacks_)
    if (!callbacks.empty())
      return "a plugin hooks the step's phases (its own memory cannot be saved)";
  if (!messaging_.Quiet())
    return "messages, signals or custom-data writes are in flight, which snapshots do not save";
  for (const ObjectType t : scene_.listing_order()) {
    const ObjectTypeDescriptor& type = scene_.type_descriptor(t);
    const RowTable* rows = scene_.rows(t);
    if (type.hash_rows != nullptr && type.save_rows == nullptr && rows != nullptr &&
        rows->size() > 0)
      return "objects of type '" + std::string(type.name) + "' have state that cannot be saved yet";
  }
  // A module that would refuse (a camera's renderer, graphs, a recording),
  // asked now (its bytes thrown away). Those every world has are installed
  // as it starts: swarmsim run asks again then, before the first step.
  for (const ModuleEntry& e : modules_) {
    StateWriter scratch;
    if (!e.instance->SaveState(*this, &scratch))
      return "the world's module '" + e.name + "' cannot save its state";
  }
  return "";
}

void World::WriteFingerprint(StateWriter* out) const {
  out->PutString(settings_.file);
  if (!file_hashed_) {
    file_hash_ = FileHash(settings_.file);
    file_hashed_ = true;
  }
  out->Put(file_hash_);
  StateHasher settings;
  settings.Add(settings_.physics.data(), settings_.physics.size());
  settings.AddValue(settings_.time_step);
  settings.AddValue(settings_.physics_substeps);
  settings.AddValue(settings_.physics_partitions);
  settings.AddValue(settings_.gravity);
  settings.AddValue(settings_.octree_resolution);
  for (const auto& [name, value] : parameters_) {
    settings.Add(name.data(), name.size() + 1);
    const std::string text = ParamToString(value);
    settings.Add(text.data(), text.size() + 1);
  }
  out->Put(settings.Digest());
  out->Put<uint64_t>(scene_.instances().size());
  out->Put<uint64_t>(scene_.object_count());
  StateHasher structure;
  scene_.AddStructure(&structure);
  structure.AddValue(scene_.structure_version());
  for (const ModuleEntry& e : modules_) structure.Add(e.name.data(), e.name.size() + 1);
  out->Put(structure.Digest());
}

void World::CheckFingerprint(StateReader* in) const {
  StateWriter mine;
  WriteFingerprint(&mine);
  StateReader expected(mine.bytes());
  struct Parts {
    std::string file;
    uint64_t file_hash, settings, robots, objects, structure;
  };
  const auto read = [](StateReader* r) {
    Parts p;
    p.file = r->GetString();
    p.file_hash = r->Get<uint64_t>();
    p.settings = r->Get<uint64_t>();
    p.robots = r->Get<uint64_t>();
    p.objects = r->Get<uint64_t>();
    p.structure = r->Get<uint64_t>();
    return p;
  };
  const Parts theirs = read(in), ours = read(&expected);
  // The two files are named only when they are two.
  const std::string of =
      theirs.file == ours.file
          ? "the snapshot is of this world's file '" + theirs.file + "'"
          : "the snapshot is of world '" + theirs.file + "', this world is '" + ours.file + "'";
  if (theirs.file_hash != ours.file_hash)
    throw Error("snapshot: " + of +
                ", and their world files differ: restore into a world "
                "loaded from the same file");
  if (theirs.robots != ours.robots || theirs.objects != ours.objects)
    throw Error("snapshot: " + of + "; it holds " + std::to_string(theirs.robots) + " robots and " +
                std::to_string(theirs.objects) + " objects, this world " +
                std::to_string(ours.robots) + " and " + std::to_string(ours.objects));
  if (theirs.settings != ours.settings)
    throw Error("snapshot: " + of + ", loaded with other settings or parameters (--set): " +
                "restore into a world loaded with the same ones");
  if (theirs.structure != ours.structure)
    throw Error("snapshot: " + of +
                "; their objects, names or modules differ (robots copied or "
                "removed at run time, or controllers given to only one of them)");
}

void World::RebuildDynamics() {
  DynamicsSettings dynamics_settings;
  dynamics_settings.gravity = settings_.gravity;
  dynamics_settings.partitions = settings_.physics_partitions;
  dynamics_settings.scheduler = scheduler_.get();
  dynamics_settings.options = settings_.physics_options;  // as Start gives them
  dynamics_->Build(scene_, dynamics_settings);
  dynamics_->MarkSimulatedJoints(&scene_);
}

std::string World::SaveState(std::span<const MetricSample> taken) {
  if (failed_) throw Error("snapshot: the world stopped after an error");
  if (stopped_) throw Error("snapshot: the world was stopped");
  if (const std::string why = SnapshotRefusal(); !why.empty()) throw Error("snapshot: " + why);
  if (!started_) Start();
  StateWriter out;
  out.PutBytes(kMagic, sizeof kMagic);
  out.Put(kVersion);
  out.Put<uint64_t>(0);  // payload size and checksum, below
  out.Put<uint64_t>(0);
  WriteFingerprint(&out);
  out.Put(settings_.seed);
  out.Put(step_count_);
  out.Put(time_);
  scene_.SaveState(&out);
  for (const ObjectType t : scene_.listing_order()) {
    const ObjectTypeDescriptor& type = scene_.type_descriptor(t);
    if (type.save_rows != nullptr && scene_.rows(t) != nullptr) type.save_rows(scene_, t, &out);
  }
  out.Put<uint64_t>(runtimes_.size());
  for (const RobotRuntime& rt : runtimes_) out.PutBytes(rt.rng.state(), sizeof(Rng));
  out.PutBytes(scene_runtime_.rng.state(), sizeof(Rng));
  SaveWrittenParameters(&out);
  out.Put<uint64_t>(taken.size() + metrics_.size());
  for (const std::span<const MetricSample> samples :
       {taken, std::span<const MetricSample>(metrics_)})
    for (const MetricSample& m : samples) {
      out.Put(m.step);
      out.Put(m.time);
      out.Put(m.instance);
      out.PutString(m.name);
      out.Put(m.value);
    }
  for (const ModuleEntry& e : modules_) {
    const size_t before = out.bytes().size();
    out.Put<uint64_t>(0);  // the module's bytes, below
    if (!e.instance->SaveState(*this, &out))
      throw Error("snapshot: the world's module '" + e.name + "' cannot save its state");
    const uint64_t size = out.bytes().size() - before - sizeof(uint64_t);
    std::memcpy(out.bytes().data() + before, &size, sizeof size);
  }
  // The engine from the scene, as a restore builds it (world_state.h).
  RebuildDynamics();
  std::string& bytes = out.bytes();
  const std::string_view payload = std::string_view(bytes).substr(kHeaderBytes);
  const uint64_t size = payload.size(), checksum = Checksum(payload);
  std::memcpy(bytes.data() + sizeof kMagic + sizeof kVersion, &size, sizeof size);
  std::memcpy(bytes.data() + sizeof kMagic + sizeof kVersion + sizeof size, &checksum,
              sizeof checksum);
  return std::move(bytes);
}

void World::RestoreState(std::string_view bytes, const Reseed* reseed) {
  if (failed_) throw Error("restore: the world stopped after an error and cannot be restored");
  if (stopped_) throw Error("restore: the world was stopped");
  // The whole payload is checked before anything changes.
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw Error("snapshot: these bytes are not a swarmsim snapshot (" +
                std::to_string(bytes.size()) + " bytes)");
  StateReader header(bytes.substr(sizeof kMagic, kHeaderBytes - sizeof kMagic));
  if (const auto version = header.Get<uint32_t>(); version != kVersion)
    throw Error("snapshot: format version " + std::to_string(version) + ", this program reads " +
                std::to_string(kVersion));
  const auto size = header.Get<uint64_t>();
  const auto checksum = header.Get<uint64_t>();
  const std::string_view payload = bytes.substr(kHeaderBytes);
  if (payload.size() != size)
    throw Error("snapshot: truncated or extended: " + std::to_string(payload.size()) +
                " bytes after the header, the header says " + std::to_string(size));
  if (Checksum(payload) != checksum)
    throw Error("snapshot: corrupt (its checksum does not match its bytes)");
  if (const std::string why = SnapshotRefusal(); !why.empty()) throw Error("restore: " + why);
  if (!started_) Start();
  StateReader in(payload);
  CheckFingerprint(&in);
  // From here on the world changes: an error (which a checked payload of
  // this world's fingerprint does not give) leaves it unusable.
  try {
    settings_.seed = in.Get<uint64_t>();
    step_count_ = in.Get<int64_t>();
    time_ = in.Get<double>();
    scene_.LoadState(&in);
    for (const ObjectType t : scene_.listing_order()) {
      const ObjectTypeDescriptor& type = scene_.type_descriptor(t);
      if (type.load_rows != nullptr && scene_.rows(t) != nullptr) type.load_rows(&scene_, t, &in);
    }
    in.Expect(in.Get<uint64_t>(), runtimes_.size(), "the number of robot random streams");
    for (RobotRuntime& rt : runtimes_) in.GetBytes(&rt.rng, sizeof(Rng));
    in.GetBytes(&scene_runtime_.rng, sizeof(Rng));
    LoadWrittenParameters(&in);
    if (reseed != nullptr) {
      // As EnsureRuntimes and the loader make them for that seed.
      if (step_count_ != 0) in.Fail("a reseed needs a snapshot of a world that has not stepped");
      settings_.seed = reseed->seed;
      for (size_t r = 0; r < runtimes_.size(); ++r) runtimes_[r].rng = Rng(reseed->seed, r);
      scene_runtime_.rng = Rng(reseed->seed, uint64_t{1} << 63);
      for (const auto& [robot, X_WR] : reseed->roots)
        scene_.SetWorldPose(scene_.instance(robot).root, X_WR);
    }
    metrics_.resize(in.GetCount(sizeof(int64_t) + sizeof(double) + sizeof(int) + sizeof(uint64_t) +
                                sizeof(double)));
    for (MetricSample& m : metrics_) {
      m.step = in.Get<int64_t>();
      m.time = in.Get<double>();
      m.instance = in.Get<int>();
      m.name = in.GetString();
      m.value = in.Get<double>();
    }
    for (const ModuleEntry& e : modules_) {
      const uint64_t module_bytes = in.GetCount(1);
      const size_t before = in.remaining();
      e.instance->LoadState(&in, this);
      if (before - in.remaining() != module_bytes)
        in.Fail("module '" + e.name + "' read " + std::to_string(before - in.remaining()) +
                " bytes of its " + std::to_string(module_bytes));
    }
    if (in.remaining() != 0) in.Fail(std::to_string(in.remaining()) + " bytes left over");
    RebuildDynamics();
  } catch (...) {
    failed_ = true;
    throw;
  }
}

}  // namespace swarmsim
