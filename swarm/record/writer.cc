#include "swarm/record/writer.h"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/paint/paint_layer.h"
#include "swarm/record/format.h"
#include "swarm/run/version.h"

namespace swarmsim::record {
namespace {

using nlohmann::json;

// What a recorded object is drawn as.
enum class Kind : uint8_t { kFrame, kShape, kLed, kProximity };

struct Tracked {  // 16 bytes
  uint32_t slot;
  int32_t root;  // slot of its robot's root (its pose is X_RO), -1: X_WO (roots, scene objects)
  uint32_t row;  // in its type's table
  Kind kind;
};

// A pose in the file's integers: position in kPositionUnit, quaternion in 1/32767.
struct QuantizedPose {  // 20 bytes
  int32_t x, y, z;
  int16_t qw, qx, qy, qz;
  bool operator==(const QuantizedPose&) const = default;
};

int32_t QuantizePosition(double metres) {
  const double v = std::round(metres / kPositionUnit);
  if (!(v > -2147483647.0)) return -2147483647;  // NaN too
  if (v > 2147483647.0) return 2147483647;
  return static_cast<int32_t>(v);
}

QuantizedPose Quantize(const Pose& X) {
  Quat q = X.q;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (norm > 0 && std::isfinite(norm))
    q = {q.w / norm, q.x / norm, q.y / norm, q.z / norm};
  else
    q = {};
  if (q.w < 0) q = {-q.w, -q.x, -q.y, -q.z};
  const auto c = [](double v) { return static_cast<int16_t>(std::lround(v * kQuaternionScale)); };
  return {QuantizePosition(X.p.x),
          QuantizePosition(X.p.y),
          QuantizePosition(X.p.z),
          c(q.w),
          c(q.x),
          c(q.y),
          c(q.z)};
}

uint8_t Channel(double v) {
  return static_cast<uint8_t>(std::lround(std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0) * 255));
}
// r, g, b, a as a little-endian u32 (bytes r, g, b, a in the file).
uint32_t PackColor(const Vec3& c, bool on) {
  return Channel(c.x) | (uint32_t{Channel(c.y)} << 8) | (uint32_t{Channel(c.z)} << 16) |
         (uint32_t{on ? 1u : 0u} << 24);
}

// A little-endian byte buffer with alignment padding.
class Bytes {
 public:
  template <typename T>
  void Put(T value) {
    const size_t at = data_.size();
    data_.resize(at + sizeof(T));
    std::memcpy(data_.data() + at, &value, sizeof(T));
  }
  void PutBytes(const void* p, size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    data_.insert(data_.end(), b, b + n);
  }
  void Pad(size_t alignment) {
    while (data_.size() % alignment != 0) data_.push_back(0);
  }
  void clear() { data_.clear(); }
  const std::vector<uint8_t>& data() const { return data_; }

 private:
  std::vector<uint8_t> data_;
};

// Ids ascending, as differences (FORMAT.md).
void PutIds(const std::vector<uint32_t>& ids, Bytes* out) {
  uint32_t last = 0;
  for (const uint32_t id : ids) {
    out->Put<uint32_t>(id - last);
    last = id;
  }
}

json ColorJson(const Vec3& c) { return json::array({c.x, c.y, c.z}); }

// A mesh asset: its file (as the loader shows it) and its geometry, in
// float precision (metres in the shape's frame, scale applied).
json MeshJson(const TriangleMesh& mesh) {
  json vertices = json::array(), triangles = json::array(), colors = json::array();
  for (const Vec3& v : mesh.vertices())
    for (const double c : {v.x, v.y, v.z}) vertices.push_back(static_cast<float>(c));
  for (const MeshTriangle& t : mesh.triangles())
    for (const uint32_t i : t.v) triangles.push_back(i);
  for (const Vec3& c : mesh.colors())
    for (const double v : {c.x, c.y, c.z}) colors.push_back(static_cast<float>(v));
  return {{"file", mesh.name()},
          {"vertices", std::move(vertices)},
          {"triangles", std::move(triangles)},
          {"colors", std::move(colors)}};
}

json ParamsJson(const ParameterSet& parameters) {
  json out = json::object();
  for (const auto& [name, value] : parameters) {
    if (const double* d = std::get_if<double>(&value))
      out[name] = *d;
    else if (const bool* b = std::get_if<bool>(&value))
      out[name] = *b;
    else
      out[name] = std::get<std::string>(value);
  }
  return out;
}

}  // namespace

struct RunRecorder::Impl {
  RecordSettings settings;
  std::filesystem::path path;
  int fd = -1;
  ZSTD_CCtx* cctx = nullptr;
  std::vector<uint8_t> chunk;  // header + compressed payload
  uint64_t bytes = 0;
  bool finished = false;

  World* world = nullptr;
  ObjectType led_type{};
  bool has_leds = false;
  const paint::PaintLayer* paint = nullptr;
  std::vector<uint8_t> paint_previous;  // rgb at the last step record (height x width x 3)

  // The recorded objects (ids) and, per robot, its id range.
  uint64_t scene_version = ~uint64_t{0};
  std::vector<Tracked> tracked;                          // (ids)
  std::vector<std::pair<uint32_t, uint32_t>> robot_ids;  // first, count (live robots)
  std::vector<int> robot_index;                          // robot of each range
  std::vector<uint32_t> color_ids, proximity_ids;        // ids of shapes and LEDs, of sensors
  std::vector<Pose> relative;                            // scratch: X_RO by slot (slots)

  // State at this step and at the last step record, by id.
  std::vector<QuantizedPose> pose, pose_previous;
  std::vector<uint32_t> color, color_previous;
  std::vector<uint16_t> reading, reading_previous;

  // Metrics: names by id, samples since the last step record.
  std::map<std::string, uint32_t, std::less<>> metric_ids;
  std::vector<std::string> metric_names;
  size_t names_written = 0;
  struct Sample {
    uint32_t name;
    int32_t robot;
    uint32_t step;
    double value;
  };
  std::vector<Sample> samples;

  int64_t records = 0;
  Bytes payload;

  void WriteChunk(ChunkKind kind, int64_t step, const std::vector<uint8_t>& raw);
  void WriteJson(ChunkKind kind, int64_t step, const json& j) {
    const std::string text = j.dump();
    WriteChunk(kind, step, std::vector<uint8_t>(text.begin(), text.end()));
  }
  json Header() const;
  void BuildScene();
  void Capture();
  void EncodeStep(bool keyframe);
  void WriteStep(const World& world);
  uint32_t MetricId(std::string_view name) {
    if (const auto it = metric_ids.find(name); it != metric_ids.end()) return it->second;
    const uint32_t id = static_cast<uint32_t>(metric_names.size());
    metric_ids.emplace(std::string(name), id);
    metric_names.emplace_back(name);
    return id;
  }
};

namespace {
// Fills in a chunk's header before its stored payload (FORMAT.md "Chunks").
void FillChunkHeader(uint8_t kind, uint32_t step, size_t stored, size_t raw, uint8_t* h) {
  std::memcpy(h, kMagic, 4);
  h[4] = kind;
  h[5] = 0;
  h[6] = h[7] = 0;
  const auto put32 = [](uint8_t* at, uint32_t v) {
    for (int i = 0; i < 4; ++i) at[i] = static_cast<uint8_t>(v >> (8 * i));
  };
  put32(h + 8, step);
  put32(h + 12, static_cast<uint32_t>(stored));
  put32(h + 16, static_cast<uint32_t>(raw));
  put32(h + 20, XXH32(h + kChunkHeaderSize, stored, 0));
}
}  // namespace

void RunRecorder::Impl::WriteChunk(ChunkKind kind, int64_t step, const std::vector<uint8_t>& raw) {
  const size_t bound = ZSTD_compressBound(raw.size());
  chunk.resize(kChunkHeaderSize + bound);
  const size_t stored = ZSTD_compressCCtx(cctx, chunk.data() + kChunkHeaderSize, bound, raw.data(),
                                          raw.size(), settings.zstd_level);
  if (ZSTD_isError(stored))
    throw Error("cannot compress a chunk of " + path.string() + ": " + ZSTD_getErrorName(stored));
  chunk.resize(kChunkHeaderSize + stored);
  FillChunkHeader(static_cast<uint8_t>(kind), static_cast<uint32_t>(step), stored, raw.size(),
                  chunk.data());
  // One write per chunk, so a reader (or a kill) never sees half of one but at the end.
  size_t done = 0;
  while (done < chunk.size()) {
    const ssize_t n = ::write(fd, chunk.data() + done, chunk.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error("cannot write " + path.string() + ": " + std::strerror(n < 0 ? errno : ENOSPC));
    done += static_cast<size_t>(n);
  }
  bytes += chunk.size();
}

json RunRecorder::Impl::Header() const {
  const WorldSettings& ws = world->settings();
  const Scene& scene = world->scene();
  json j;
  j["format"] = kFormatName;
  j["version"] = json::array({kVersionMajor, kVersionMinor});
  j["swarmsim_version"] = Version();
  j["world"] = settings.world_file;
  j["world_dir"] = ws.directory.string();
  j["seed"] = ws.seed;
  j["dt"] = ws.time_step;
  j["steps_planned"] = settings.steps_planned;
  j["record_every"] = settings.every;
  j["keyframe_every"] = settings.keyframe_every;
  j["position_unit"] = kPositionUnit;
  j["quaternion_unit"] = 1.0 / kQuaternionScale;
  j["physics"] = ws.physics;
  // The floor: the paint layer's area, else what the scene's objects and the map cover.
  double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  const auto cover = [&](double x0, double y0, double x1, double y1) {
    lo_x = std::min(lo_x, x0), lo_y = std::min(lo_y, y0);
    hi_x = std::max(hi_x, x1), hi_y = std::max(hi_y, y1);
  };
  if (paint != nullptr) {
    const paint::PaintSettings& ps = paint->settings();
    cover(ps.min_x, ps.min_y, ps.max_x, ps.max_y);
  } else {
    const auto shapes = scene.shapes();
    const auto owners = scene.shape_owners();
    for (size_t r = 0; r < shapes.size(); ++r) {
      const uint32_t slot = owners[r];
      const Pose& X = scene.world_pose_at(slot);
      Vec3 half{0, 0, 0};  // robots: their origins
      if (scene.instance_of_at(slot) < 0) {
        const ShapeData& s = shapes[r];
        // A box's footprint exactly (its rotated half extents), others by their radius.
        if (s.kind == ShapeKind::kBox) {
          for (const Vec3& axis :
               {Vec3{s.size.x / 2, 0, 0}, Vec3{0, s.size.y / 2, 0}, Vec3{0, 0, s.size.z / 2}}) {
            const Vec3 a = X.q.Rotate(axis);
            half = {half.x + std::abs(a.x), half.y + std::abs(a.y), 0};
          }
        } else {
          half = {s.BoundingRadius(), s.BoundingRadius(), 0};
        }
      }
      cover(X.p.x - half.x, X.p.y - half.y, X.p.x + half.x, X.p.y + half.y);
    }
    if (const EnvironmentMap* map = scene.environment(); map != nullptr && !map->boxes.empty())
      cover(map->lo.x, map->lo.y, map->hi.x, map->hi.y);
    if (!(hi_x > lo_x) || !(hi_y > lo_y)) lo_x = lo_y = -1, hi_x = hi_y = 1;
  }
  j["floor"] = {{"min", {lo_x, lo_y}}, {"max", {hi_x, hi_y}}};
  if (const EnvironmentMap* map = scene.environment(); map != nullptr) {
    json boxes = json::array();
    for (const EnvironmentBox& b : map->boxes)
      boxes.push_back({b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z});
    j["environment"] = {{"source", map->source}, {"boxes", std::move(boxes)}};
  } else {
    j["environment"] = nullptr;
  }
  if (paint != nullptr) {
    const paint::PaintSettings& ps = paint->settings();
    j["paint"] = {{"min", {ps.min_x, ps.min_y}}, {"max", {ps.max_x, ps.max_y}},
                  {"resolution", ps.resolution}, {"width", paint->width()},
                  {"height", paint->height()},   {"background", ColorJson(ps.background)}};
  } else {
    j["paint"] = nullptr;
  }
  j["metrics"] = metric_names;
  return j;
}

// The recorded objects: robots in index order (each its objects in
// hierarchy order, root first), then the scene's objects in slot order.
void RunRecorder::Impl::BuildScene() {
  const Scene& scene = world->scene();
  scene_version = scene.structure_version();
  tracked.clear();
  robot_ids.clear();
  robot_index.clear();
  color_ids.clear();
  proximity_ids.clear();
  const ObjectType shape_type = ObjectType::kShape, sensor_type = ObjectType::kProximitySensor;
  const auto kind_of = [&](uint32_t slot, Kind* kind) {
    const ObjectType t = scene.type_at(slot);
    if (t == shape_type)
      *kind = Kind::kShape;
    else if (t == sensor_type)
      *kind = Kind::kProximity;
    else if (has_leds && t == led_type)
      *kind = Kind::kLed;
    else
      return false;
    return true;
  };
  const auto led_row = [&](uint32_t slot) -> const LedRow& {
    return static_cast<const Rows<LedRow>&>(*scene.rows(led_type)).rows[scene.row_at(slot)];
  };
  json meshes = json::array();
  std::unordered_map<const TriangleMesh*, size_t> mesh_of;
  // One object's description; `parent` as the format says.
  const auto describe = [&](const Tracked& t, const std::string& name, int64_t parent) {
    json o;
    o["name"] = name;
    o["parent"] = parent;
    switch (t.kind) {
      case Kind::kFrame: o["type"] = "frame"; break;
      case Kind::kShape: {
        const ShapeData& s = scene.shapes()[t.row];
        o["type"] = "shape";
        o["shape"] = ToString(s.kind);
        o["size"] = {s.size.x, s.size.y, s.size.z};
        o["color"] = ColorJson(s.color);
        o["dynamic"] = s.dynamic;
        if (s.kind == ShapeKind::kMesh && s.mesh != nullptr) {
          // The asset once per scene chunk, shared by every shape (and copy) using it.
          auto [it, added] = mesh_of.emplace(s.mesh.get(), meshes.size());
          if (added) meshes.push_back(MeshJson(*s.mesh));
          o["mesh"] = it->second;
          o["mesh_colors"] = s.mesh_colors && !s.mesh->colors().empty();
        }
        break;
      }
      case Kind::kLed: {
        const LedRow& led = led_row(t.slot);
        o["type"] = "led";
        o["radius"] = led.radius;
        o["color"] = ColorJson(led.color);
        o["on"] = led.on;
        break;
      }
      case Kind::kProximity: {
        const ProximitySensorData& p = scene.proximity_sensors()[t.row];
        o["type"] = "proximity_sensor";
        o["range"] = p.range;
        o["volume"] = ToString(p.volume);
        if (p.volume != ProximityVolume::kRay) o["angle"] = p.more->angle;
        break;
      }
    }
    return o;
  };
  // The nearest recorded ancestor of `slot`, by `id_of_slot`.
  std::unordered_map<uint32_t, uint32_t> id_of_slot;
  const auto parent_id = [&](uint32_t slot) -> int64_t {
    for (int32_t p = scene.parent_at(slot); p >= 0; p = scene.parent_at(static_cast<uint32_t>(p)))
      if (const auto it = id_of_slot.find(static_cast<uint32_t>(p)); it != id_of_slot.end())
        return it->second;
    return -1;
  };

  json templates = json::array(), robots = json::array(), objects = json::array();
  std::unordered_map<std::string, size_t> template_of;
  const auto instances = scene.instances();
  for (size_t i = 0; i < instances.size(); ++i) {
    const ModelInstance& robot = instances[i];
    if (!robot.alive) continue;
    const uint32_t first = static_cast<uint32_t>(tracked.size());
    const uint32_t root = scene.SlotOf(robot.root);
    json list = json::array();
    for (const uint32_t slot : robot.objects) {
      Kind kind = Kind::kFrame;
      if (!kind_of(slot, &kind) && slot != root) continue;
      const Tracked t{slot, slot == root ? -1 : static_cast<int32_t>(root), scene.row_at(slot),
                      kind};
      const int64_t parent = slot == root ? -1 : parent_id(slot) - first;
      list.push_back(describe(t, slot == root ? std::string() : scene.name_at(slot), parent));
      id_of_slot[slot] = static_cast<uint32_t>(tracked.size());
      tracked.push_back(t);
    }
    const uint32_t count = static_cast<uint32_t>(tracked.size()) - first;
    std::string key = list.dump();
    auto [it, added] = template_of.emplace(std::move(key), templates.size());
    if (added) templates.push_back({{"objects", std::move(list)}});
    json entry = {{"index", i},
                  {"name", robot.name},
                  {"model", robot.model_name},
                  {"template", it->second},
                  {"first", first},
                  {"count", count}};
    const SharedParameters& parameters = world->runtime(static_cast<int>(i)).parameters;
    entry["parameters"] = parameters ? ParamsJson(*parameters) : json::object();
    robots.push_back(std::move(entry));
    robot_ids.emplace_back(first, count);
    robot_index.push_back(static_cast<int>(i));
  }
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    Kind kind = Kind::kFrame;
    if (!scene.alive_at(slot) || scene.instance_of_at(slot) >= 0 || !kind_of(slot, &kind)) continue;
    const Tracked t{slot, -1, scene.row_at(slot), kind};
    json o = describe(t, scene.name_at(slot), parent_id(slot));
    o["id"] = tracked.size();
    objects.push_back(std::move(o));
    id_of_slot[slot] = static_cast<uint32_t>(tracked.size());
    tracked.push_back(t);
  }
  for (uint32_t id = 0; id < tracked.size(); ++id) {
    if (tracked[id].kind == Kind::kShape || tracked[id].kind == Kind::kLed) color_ids.push_back(id);
    if (tracked[id].kind == Kind::kProximity) proximity_ids.push_back(id);
  }
  const size_t n = tracked.size();
  pose.assign(n, {});
  pose_previous.assign(n, {});
  color.assign(n, 0);
  color_previous.assign(n, 0);
  reading.assign(n, 0);
  reading_previous.assign(n, 0);
  WriteJson(ChunkKind::kScene, world->step_count(),
            {{"object_count", n},
             {"templates", std::move(templates)},
             {"robots", std::move(robots)},
             {"objects", std::move(objects)}});
}

// This step's poses, colours and readings, robots in parallel.
void RunRecorder::Impl::Capture() {
  const Scene& scene = world->scene();
  relative.resize(scene.slot_count());
  const auto joints = scene.joints();
  const auto shapes = scene.shapes();
  const auto sensors = scene.proximity_sensors();
  const Rows<LedRow>* leds =
      has_leds ? &static_cast<const Rows<LedRow>&>(*scene.rows(led_type)) : nullptr;
  const auto capture = [&](uint32_t id) {
    const Tracked& t = tracked[id];
    pose[id] = Quantize(t.root < 0 ? scene.world_pose_at(t.slot) : relative[t.slot]);
    switch (t.kind) {
      case Kind::kFrame: break;
      case Kind::kShape: color[id] = PackColor(shapes[t.row].color, true); break;
      case Kind::kLed: {
        const LedRow& led = leds->rows[t.row];
        color[id] = PackColor(led.color, led.on);
        break;
      }
      case Kind::kProximity: {
        const ProximitySensorData& p = sensors[t.row];
        uint16_t r = kNoDetection;
        if (p.detected && p.range > 0)
          r = static_cast<uint16_t>(
              std::lround(std::clamp(p.distance / p.range, 0.0, 1.0) * 65534));
        reading[id] = r;
        break;
      }
    }
  };
  world->scheduler().ParallelFor(
      0, static_cast<int64_t>(robot_ids.size()), kRobotGrain, [&](int64_t begin, int64_t end) {
        for (int64_t r = begin; r < end; ++r) {
          // X_RO of every object of the robot from the local poses, parents first:
          // a rigid part's stays exactly the same from step to step.
          const ModelInstance& robot = scene.instance(robot_index[r]);
          const uint32_t root = scene.SlotOf(robot.root);
          relative[root] = Pose{};
          for (const uint32_t slot : robot.objects) {
            if (slot == root) continue;
            const uint32_t p = static_cast<uint32_t>(scene.parent_at(slot));
            const Pose frame = scene.type_at(p) == ObjectType::kJoint
                                   ? relative[p] * joints[scene.row_at(p)].Motion()
                                   : relative[p];
            relative[slot] = frame * scene.local_pose_at(slot);
          }
          const auto [first, count] = robot_ids[r];
          for (uint32_t id = first; id < first + count; ++id) capture(id);
        }
      });
  const uint32_t scene_first =
      robot_ids.empty() ? 0 : robot_ids.back().first + robot_ids.back().second;
  for (uint32_t id = scene_first; id < tracked.size(); ++id) capture(id);
}

void RunRecorder::Impl::EncodeStep(bool keyframe) {
  Bytes& out = payload;
  out.clear();
  out.Put<double>(world->time());
  out.Put<uint32_t>(static_cast<uint32_t>(records));
  out.Put<uint32_t>(0);
  std::vector<uint32_t> ids;
  // Poses.
  for (uint32_t id = 0; id < tracked.size(); ++id)
    if (keyframe || !(pose[id] == pose_previous[id])) ids.push_back(id);
  out.Put<uint32_t>(static_cast<uint32_t>(ids.size()));
  PutIds(ids, &out);
  const auto put_ints = [&](auto field) {
    for (const uint32_t id : ids) {
      using T = std::remove_reference_t<decltype(pose[id].*field)>;
      const T now = pose[id].*field;
      if (keyframe) {
        out.Put<T>(now);
      } else {
        // Wrapping difference, as unsigned.
        using U = std::make_unsigned_t<T>;
        out.Put<U>(static_cast<U>(static_cast<U>(now) - static_cast<U>(pose_previous[id].*field)));
      }
    }
  };
  put_ints(&QuantizedPose::x);
  put_ints(&QuantizedPose::y);
  put_ints(&QuantizedPose::z);
  put_ints(&QuantizedPose::qw);
  put_ints(&QuantizedPose::qx);
  put_ints(&QuantizedPose::qy);
  put_ints(&QuantizedPose::qz);
  out.Pad(4);
  // Colours.
  ids.clear();
  for (const uint32_t id : color_ids)
    if (keyframe || color[id] != color_previous[id]) ids.push_back(id);
  out.Put<uint32_t>(static_cast<uint32_t>(ids.size()));
  PutIds(ids, &out);
  for (const uint32_t id : ids) out.Put<uint32_t>(color[id]);
  // Proximity readings.
  ids.clear();
  for (const uint32_t id : proximity_ids)
    if (keyframe || reading[id] != reading_previous[id]) ids.push_back(id);
  out.Put<uint32_t>(static_cast<uint32_t>(ids.size()));
  PutIds(ids, &out);
  for (const uint32_t id : ids) out.Put<uint16_t>(reading[id]);
  out.Pad(4);
  // Paint cells.
  ids.clear();
  if (paint != nullptr) {
    const std::vector<uint8_t>& rgb = paint->rgb();
    const int width = paint->width();
    if (paint_previous.size() != rgb.size()) paint_previous.assign(rgb.size(), 0);
    const uint32_t cells = static_cast<uint32_t>(rgb.size() / 3);
    for (uint32_t c = 0; c < cells; ++c) {
      const bool changed = std::memcmp(&rgb[3 * c], &paint_previous[3 * c], 3) != 0;
      if (keyframe ? paint->painted(static_cast<int>(c % width), static_cast<int>(c / width))
                   : changed)
        ids.push_back(c);
    }
    out.Put<uint32_t>(static_cast<uint32_t>(ids.size()));
    PutIds(ids, &out);
    for (const uint32_t c : ids) {
      out.PutBytes(&rgb[3 * c], 3);
      out.Put<uint8_t>(255);
    }
    paint_previous = rgb;
  } else {
    out.Put<uint32_t>(0);
  }
  // Metrics.
  const size_t first_name = keyframe ? 0 : names_written;
  out.Put<uint32_t>(static_cast<uint32_t>(first_name));
  out.Put<uint32_t>(static_cast<uint32_t>(metric_names.size() - first_name));
  for (size_t i = first_name; i < metric_names.size(); ++i) {
    const std::string& name = metric_names[i];
    out.Put<uint16_t>(static_cast<uint16_t>(std::min<size_t>(name.size(), 65535)));
    out.PutBytes(name.data(), std::min<size_t>(name.size(), 65535));
  }
  names_written = metric_names.size();
  out.Pad(4);
  out.Put<uint32_t>(static_cast<uint32_t>(samples.size()));
  for (const Sample& s : samples) out.Put<uint32_t>(s.name);
  for (const Sample& s : samples) out.Put<int32_t>(s.robot);
  for (const Sample& s : samples) out.Put<uint32_t>(s.step);
  out.Pad(8);
  for (const Sample& s : samples) out.Put<double>(s.value);
  samples.clear();
}

void RunRecorder::Impl::WriteStep(const World& w) {
  bool keyframe = records % settings.keyframe_every == 0;
  if (w.scene().structure_version() != scene_version) {
    BuildScene();
    keyframe = true;
  }
  Capture();
  EncodeStep(keyframe);
  WriteChunk(keyframe ? ChunkKind::kKeyframe : ChunkKind::kDelta, w.step_count(), payload.data());
  ++records;
  pose_previous.swap(pose);
  color_previous.swap(color);
  reading_previous.swap(reading);
}

RunRecorder::RunRecorder(const RecordSettings& settings) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.settings = settings;
  r.settings.every = std::max<int64_t>(1, settings.every);
  r.settings.keyframe_every = std::max<int64_t>(1, settings.keyframe_every);
  r.path = settings.out_dir / kRecordingFileName;
  r.fd = ::open(r.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (r.fd < 0) throw Error("cannot create " + r.path.string() + ": " + std::strerror(errno));
  r.cctx = ZSTD_createCCtx();
}

RunRecorder::~RunRecorder() {
  if (impl_->cctx != nullptr) ZSTD_freeCCtx(impl_->cctx);
  if (impl_->fd >= 0) ::close(impl_->fd);
}

void RunRecorder::Start(World* world) {
  Impl& r = *impl_;
  r.world = world;
  r.has_leds = world->scene().FindType(kLedTypeName, &r.led_type);
  if (const Module* m = world->find_module("paint"); m != nullptr)
    r.paint = dynamic_cast<const paint::PaintLayer*>(m);
  for (const std::string& name : r.settings.metric_names) r.MetricId(name);
  r.WriteJson(ChunkKind::kHeader, 0, r.Header());
  r.names_written = 0;
  r.WriteStep(*world);
}

void RunRecorder::Record(const World& world, std::vector<MetricSample>* out) {
  Impl& r = *impl_;
  const int64_t step = world.step_count();
  // This step's samples (the runner takes them after every step).
  for (const MetricSample& m : *out)
    if (m.step == step)
      r.samples.push_back({r.MetricId(m.name), m.instance, static_cast<uint32_t>(m.step), m.value});
  if (step % r.settings.every != 0) return;
  r.WriteStep(world);
}

void RunRecorder::ListOutputs(std::vector<OutputFile>* out) const {
  out->push_back({"recording", kRecordingFileName,
                  std::to_string(impl_->records) + " step records (swarmsim view)"});
}

void RunRecorder::Finish(int64_t steps, const std::string& status, const std::string& error) {
  Impl& r = *impl_;
  if (r.finished || r.fd < 0) return;
  r.finished = true;
  json j = {{"steps", steps}, {"status", status}};
  if (!error.empty()) j["error"] = error;
  try {
    r.WriteJson(ChunkKind::kEnd, steps, j);
  } catch (const Error&) {
    // The steps are all there; a viewer just does not learn that the run ended.
  }
}

int64_t RunRecorder::step_records() const { return impl_->records; }
uint64_t RunRecorder::bytes_written() const { return impl_->bytes; }

std::string EncodeChunk(uint8_t kind, uint32_t step, const std::string& payload) {
  std::string out(kChunkHeaderSize + ZSTD_compressBound(payload.size()), '\0');
  auto* h = reinterpret_cast<uint8_t*>(out.data());
  const size_t stored = ZSTD_compress(h + kChunkHeaderSize, out.size() - kChunkHeaderSize,
                                      payload.data(), payload.size(), 3);
  if (ZSTD_isError(stored)) throw Error(std::string("zstd: ") + ZSTD_getErrorName(stored));
  out.resize(kChunkHeaderSize + stored);
  FillChunkHeader(kind, step, stored, payload.size(), reinterpret_cast<uint8_t*>(out.data()));
  return out;
}

RunRecorder* AddRecorder(World* world, const RecordSettings& settings) {
  auto recorder = std::make_unique<RunRecorder>(settings);
  RunRecorder* raw = recorder.get();
  world->AddObserver(std::move(recorder));
  return raw;
}

}  // namespace swarmsim::record
