#include "swarm/record/writer.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <span>
#include <unordered_map>

#include "framework/error.h"
#include "framework/floor_layer.h"
#include "framework/memory_forecast.h"
#include "framework/object_type.h"
#include "framework/scheduler.h"
#include "framework/utf8.h"
#include "framework/visual.h"
#include "framework/world.h"
#include "swarm/record/chunk_writer.h"
#include "swarm/record/format.h"
#include "swarm/run/version.h"

namespace swarmsim::record {
namespace {

using nlohmann::json;

// A chunk's JSON text. Names and texts from the world (a parameter's value,
// a script's error message holding a binary payload) may be bytes that are
// not UTF-8: they are written with U+FFFD in their place (json's dump()
// threw: the recording failed a run that ran without it, and its end chunk,
// with the script's error, was never written).
std::string JsonText(const json& j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

// The hook that says what an object of a type looks like (framework/visual.h).
using VisualHook = void (*)(const Scene&, ObjectType, uint32_t, ObjectVisual*);

struct Tracked {  // 16 bytes
  uint32_t slot;
  int32_t root;     // slot of its robot's root (its pose is X_RO), -1: X_WO (roots, scene objects)
  uint32_t row;     // in its type's table
  ObjectType type;  // its type, whose `visual` hook draws it
  VisualKind kind;  // kNone: a robot's root frame, not drawn
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
  std::unique_ptr<ChunkWriter> file;
  bool finished = false;

  World* world = nullptr;
  const FloorLayer* paint = nullptr;    // the world's floor layer (the paint layer), if any
  std::vector<uint8_t> paint_previous;  // rgb at the last step record (height x width x 3)

  // The recorded objects (ids) and, per robot, its id range.
  uint64_t scene_version = ~uint64_t{0};
  std::vector<Tracked> tracked;                          // (ids)
  std::vector<std::pair<uint32_t, uint32_t>> robot_ids;  // first, count (live robots)
  std::vector<int> robot_index;                          // robot of each range
  // Every object of every robot (joints too: their motion moves what hangs
  // below), robots in id order, each in hierarchy order, root first; per
  // robot its range. By plan entry: X_RO, the local pose it was made from,
  // and whether it changed at this capture.
  struct PlanEntry {  // 16 bytes
    uint32_t slot;
    int32_t parent;      // entry of the parent, -1: the root
    uint32_t id;         // recorded id, kNotRecorded
    uint32_t joint_row;  // the parent's row in the joint table, kNotRecorded: not a joint
  };
  static constexpr uint32_t kNotRecorded = ~uint32_t{0};
  std::vector<PlanEntry> plan;
  std::vector<std::pair<uint32_t, uint32_t>> robot_plan;  // begin, end (robot ranges)
  std::vector<Pose> relative, relative_from;              // (plan)
  std::vector<uint8_t> moved;                             // (plan)
  bool capture_all = true;                                // after a new scene: every pose afresh

  // Objects whose type declares links (ids, ascending), and the recorded id
  // of every recorded object's slot.
  std::vector<uint32_t> link_ids;
  std::unordered_map<uint32_t, uint32_t> id_of_slot;
  std::vector<ObjectId> linked;  // scratch

  // The state at this step, by id.
  std::vector<QuantizedPose> pose;
  std::vector<uint32_t> color;
  std::vector<uint16_t> reading;

  // Metrics: names by id, samples since the last step record.
  std::map<std::string, uint32_t, std::less<>> metric_ids;
  std::vector<std::string> metric_names;
  size_t names_written = 0;
  std::vector<SampleRow> samples;
  // Where the world's samples not taken yet stand (Record).
  uint64_t metrics_taken = 0;
  size_t metrics_seen = 0;

  int64_t records = 0;

  json Header() const;
  void BuildScene();
  void Capture();
  void WriteStep(const World& world);
  // Every keyframe holds each recorded object's id and pose, and each
  // colour's and ray length's: a world whose keyframes would not fit in a
  // chunk (FORMAT.md, "Limits") is refused as its scene is listed, not a
  // step into the run. Throws swarmsim::Error.
  void CheckKeyframeFits(size_t objects, const SceneLists& lists) const;
  uint32_t MetricId(std::string_view name) {
    if (const auto it = metric_ids.find(name); it != metric_ids.end()) return it->second;
    const uint32_t id = static_cast<uint32_t>(metric_names.size());
    metric_ids.emplace(std::string(name), id);
    // As metrics.csv writes it (FORMAT.md: UTF-8 bytes): U+FFFD for bytes
    // that are not UTF-8 (sim.recordMetric('\xff', v) was written raw).
    metric_names.push_back(ValidUtf8(name));
    return id;
  }
};

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
    const FloorArea ps = paint->floor_area();
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
    const FloorArea ps = paint->floor_area();
    j["paint"] = {{"min", {ps.min_x, ps.min_y}}, {"max", {ps.max_x, ps.max_y}},
                  {"resolution", ps.resolution}, {"width", ps.width},
                  {"height", ps.height},         {"background", ColorJson(ps.background)}};
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
  plan.clear();
  robot_plan.clear();
  // What the object at `slot` looks like, by its type's declaration; false: not drawn.
  const auto visual_of = [&](uint32_t slot, ObjectVisual* visual) {
    const VisualHook hook = scene.type_descriptor(scene.type_at(slot)).visual;
    if (hook == nullptr) return false;
    hook(scene, scene.type_at(slot), scene.row_at(slot), visual);
    return visual->kind != VisualKind::kNone;
  };
  json meshes = json::array();
  std::unordered_map<const TriangleMesh*, size_t> mesh_of;
  // One object's description (FORMAT.md "Scene chunk"): its type's name
  // and what its visual declares; `parent` as the format says.
  const auto describe = [&](const Tracked& t, const ObjectVisual& v, const std::string& name,
                            int64_t parent) {
    json o;
    o["name"] = name;
    o["parent"] = parent;
    if (t.kind == VisualKind::kNone) {
      o["type"] = "frame";
      return o;
    }
    o["type"] = scene.type_name(t.type);
    o["visual"] = ToString(v.kind);
    if (IsSolid(v.kind)) {
      o["shape"] = ToString(v.kind);
      o["size"] = {v.size.x, v.size.y, v.size.z};
      o["color"] = ColorJson(v.color);
      if (v.kind == VisualKind::kMesh && v.mesh != nullptr) {
        // The asset once per scene chunk, shared by every object (and copy) using it.
        auto [it, added] = mesh_of.emplace(v.mesh, meshes.size());
        if (added) meshes.push_back(MeshJson(*v.mesh));
        o["mesh"] = it->second;
        o["mesh_colors"] = v.mesh_colors;
      }
    } else if (v.kind == VisualKind::kLight) {
      o["radius"] = v.size.x;
      o["color"] = ColorJson(v.color);
      o["on"] = v.on;
    } else if (v.kind == VisualKind::kRay) {
      o["range"] = v.size.x;
      o["color"] = ColorJson(v.color);
    }
    return o;
  };
  // The nearest recorded ancestor of `slot`, by `id_of_slot`.
  id_of_slot.clear();
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
    const uint32_t plan_begin = static_cast<uint32_t>(plan.size());
    std::unordered_map<uint32_t, int32_t> entry_of_slot;
    for (const uint32_t slot : robot.objects) {
      PlanEntry e{slot, -1, kNotRecorded, kNotRecorded};
      if (slot != root) {
        const uint32_t parent = static_cast<uint32_t>(scene.parent_at(slot));
        e.parent = entry_of_slot.at(parent);
        if (scene.type_at(parent) == ObjectType::kJoint) e.joint_row = scene.row_at(parent);
      }
      entry_of_slot[slot] = static_cast<int32_t>(plan.size());
      ObjectVisual visual;
      const bool drawn = visual_of(slot, &visual);
      const bool recorded = drawn || slot == root;
      if (recorded) e.id = static_cast<uint32_t>(tracked.size());
      plan.push_back(e);
      if (!recorded) continue;
      const Tracked t{slot, slot == root ? -1 : static_cast<int32_t>(root), scene.row_at(slot),
                      scene.type_at(slot), drawn ? visual.kind : VisualKind::kNone};
      const int64_t parent = slot == root ? -1 : parent_id(slot) - first;
      list.push_back(
          describe(t, visual, slot == root ? std::string() : scene.name_at(slot), parent));
      id_of_slot[slot] = static_cast<uint32_t>(tracked.size());
      tracked.push_back(t);
    }
    const uint32_t count = static_cast<uint32_t>(tracked.size()) - first;
    std::string key = JsonText(list);
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
    robot_plan.emplace_back(plan_begin, static_cast<uint32_t>(plan.size()));
  }
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot) {
    ObjectVisual visual;
    if (!scene.alive_at(slot) || scene.instance_of_at(slot) >= 0 || !visual_of(slot, &visual))
      continue;
    const Tracked t{slot, -1, scene.row_at(slot), scene.type_at(slot), visual.kind};
    json o = describe(t, visual, scene.name_at(slot), parent_id(slot));
    o["id"] = tracked.size();
    objects.push_back(std::move(o));
    id_of_slot[slot] = static_cast<uint32_t>(tracked.size());
    tracked.push_back(t);
  }
  link_ids.clear();
  for (uint32_t id = 0; id < tracked.size(); ++id)
    if (tracked[id].kind != VisualKind::kNone &&
        scene.type_descriptor(tracked[id].type).links != nullptr)
      link_ids.push_back(id);
  SceneLists lists;
  // Every drawn object's colour; rays' lengths too.
  for (uint32_t id = 0; id < tracked.size(); ++id) {
    if (tracked[id].kind != VisualKind::kNone) lists.color_ids.push_back(id);
    if (tracked[id].kind == VisualKind::kRay) lists.proximity_ids.push_back(id);
  }
  const size_t n = tracked.size();
  CheckKeyframeFits(n, lists);
  lists.object_count = n;
  pose.assign(n, {});
  color.assign(n, 0);
  reading.assign(n, 0);
  relative.assign(plan.size(), Pose{});
  relative_from.assign(plan.size(), Pose{});
  moved.assign(plan.size(), 1);
  capture_all = true;
  const json j = {{"object_count", n},
                  {"templates", std::move(templates)},
                  {"robots", std::move(robots)},
                  {"objects", std::move(objects)},
                  {"meshes", std::move(meshes)}};
  file->AddScene(static_cast<uint32_t>(world->step_count()), JsonText(j), std::move(lists));
}

// This step's poses, and colours and ray lengths as the objects' types
// declare them (their `visual` hooks), robots in parallel. A robot
// object's X_RO is made from the local poses down its branch, and only
// where something on the branch moved (a joint, a local pose that changed):
// the 24 sensors of a ring are not quantised again every step.
void RunRecorder::Impl::Capture() {
  const Scene& scene = world->scene();
  const auto joints = scene.joints();
  // Each type's hook, by ObjectType value.
  std::array<VisualHook, kMaxObjectTypes> hooks{};
  for (size_t k = 0; k < scene.types().size(); ++k) hooks[k] = scene.types()[k]->visual;
  const bool all = capture_all;
  // `entry`: its plan entry (robots' objects), or -1 (scene objects).
  const auto capture = [&](uint32_t id, int64_t entry) {
    const Tracked& t = tracked[id];
    if (t.root < 0)
      pose[id] = Quantize(scene.world_pose_at(t.slot));
    else if (moved[entry])
      pose[id] = Quantize(relative[entry]);
    if (t.kind == VisualKind::kNone) return;
    ObjectVisual v;
    hooks[static_cast<size_t>(t.type)](scene, t.type, t.row, &v);
    color[id] = PackColor(v.color, v.on);
    if (t.kind == VisualKind::kRay) {
      const double length = v.size.x;
      uint16_t r = kNoDetection;
      if (v.hit >= 0 && length > 0)
        r = static_cast<uint16_t>(std::lround(std::clamp(v.hit / length, 0.0, 1.0) * 65534));
      reading[id] = r;
    }
  };
  world->scheduler().ParallelFor(
      0, static_cast<int64_t>(robot_ids.size()), kRobotGrain, [&](int64_t begin, int64_t end) {
        for (int64_t r = begin; r < end; ++r) {
          const auto [plan_begin, plan_end] = robot_plan[r];
          for (uint32_t k = plan_begin; k < plan_end; ++k) {
            const PlanEntry& e = plan[k];
            if (e.parent < 0) {
              moved[k] = 0;  // the root's frame, in itself: identity
            } else {
              const Pose& X_PO = scene.local_pose_at(e.slot);
              const bool joint = e.joint_row != kNotRecorded;
              const bool changed = all || joint || moved[e.parent] ||
                                   std::memcmp(&X_PO, &relative_from[k], sizeof(Pose)) != 0;
              moved[k] = changed;
              if (changed) {
                relative_from[k] = X_PO;
                const Pose& X_RP = relative[e.parent];
                relative[k] = (joint ? X_RP * joints[e.joint_row].Motion() : X_RP) * X_PO;
              }
            }
            if (e.id != kNotRecorded) capture(e.id, k);
          }
        }
      });
  const uint32_t scene_first =
      robot_ids.empty() ? 0 : robot_ids.back().first + robot_ids.back().second;
  for (uint32_t id = scene_first; id < tracked.size(); ++id) capture(id, -1);
  capture_all = false;
}

void RunRecorder::Impl::CheckKeyframeFits(size_t objects, const SceneLists& lists) const {
  const double bytes = (4.0 + kPoseBytes) * static_cast<double>(objects) +
                       8.0 * static_cast<double>(lists.color_ids.size()) +
                       6.0 * static_cast<double>(lists.proximity_ids.size());
  const double limit = settings.max_chunk_raw_bytes;
  if (bytes <= limit) return;
  const int robots = world->robot_count();
  throw Error("the recording: every keyframe of this world would hold at least " +
              FormatSize(bytes) + " (" + GroupThousands(static_cast<int64_t>(objects)) +
              " recorded objects), past the " + FormatSize(limit) +
              " a recording chunk may hold (what readers accept: FORMAT.md, \"Limits\"); " +
              (robots > 0
                   ? "record fewer robots (about " +
                         GroupThousands(static_cast<int64_t>(std::floor(robots * limit / bytes))) +
                         " of these " + GroupThousands(robots) + " would fit)"
                   : std::string("record fewer objects")) +
              " or run this one without recording");
}

void RunRecorder::Impl::WriteStep(const World& w) {
  bool keyframe = records % settings.keyframe_every == 0;
  if (w.scene().structure_version() != scene_version) {
    BuildScene();
    keyframe = true;
  }
  Capture();
  std::unique_ptr<StepSnapshot> snap = file->TakeSnapshot();
  snap->step = static_cast<uint32_t>(w.step_count());
  snap->time = w.time();
  snap->record = static_cast<uint32_t>(records);
  snap->keyframe = keyframe;
  snap->pose = pose;
  snap->color = color;
  snap->reading = reading;
  // Paint: every painted cell in a keyframe, else the cells that changed.
  if (paint != nullptr) {
    const std::span<const uint8_t> rgb = paint->floor_rgb();
    const uint32_t width = static_cast<uint32_t>(paint->floor_area().width);
    if (paint_previous.size() != rgb.size()) paint_previous.assign(rgb.size(), 0);
    const uint32_t cells = static_cast<uint32_t>(rgb.size() / 3);
    for (uint32_t c = 0; c < cells; ++c) {
      const bool take =
          keyframe ? paint->floor_marked(static_cast<int>(c % width), static_cast<int>(c / width))
                   : std::memcmp(&rgb[3 * c], &paint_previous[3 * c], 3) != 0;
      if (!take) continue;
      snap->paint_cells.push_back(c);
      snap->paint_rgba.push_back(rgb[3 * c] | (uint32_t{rgb[3 * c + 1]} << 8) |
                                 (uint32_t{rgb[3 * c + 2]} << 16) | (uint32_t{255} << 24));
    }
    paint_previous.assign(rgb.begin(), rgb.end());
  }
  // Metric names (all of them in a keyframe) and the samples since the last record.
  snap->first_name = static_cast<uint32_t>(keyframe ? 0 : names_written);
  snap->names.assign(metric_names.begin() + snap->first_name, metric_names.end());
  names_written = metric_names.size();
  snap->samples.swap(samples);
  samples.clear();
  // Links: every linked pair of recorded objects, by the linking object's id.
  snap->links = !link_ids.empty();
  snap->link_from.clear();
  snap->link_to.clear();
  const Scene& scene = w.scene();
  for (const uint32_t id : link_ids) {
    const Tracked& t = tracked[id];
    linked.clear();
    scene.type_descriptor(t.type).links(scene, t.type, t.row, &linked);
    for (const ObjectId other : linked) {
      if (!scene.IsValid(other)) continue;
      const auto it = id_of_slot.find(scene.SlotOf(other));
      if (it == id_of_slot.end()) continue;  // not recorded
      snap->link_from.push_back(id);
      snap->link_to.push_back(it->second);
    }
  }
  file->AddStep(std::move(snap));
  ++records;
}

RunRecorder::RunRecorder(const RecordSettings& settings) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.settings = settings;
  r.settings.every = std::max<int64_t>(1, settings.every);
  r.settings.keyframe_every = std::max<int64_t>(1, settings.keyframe_every);
  r.file = std::make_unique<ChunkWriter>(settings.out_dir / kRecordingFileName, settings.zstd_level,
                                         settings.max_chunk_raw_bytes);
}

RunRecorder::~RunRecorder() = default;

void RunRecorder::Start(World* world) {
  Impl& r = *impl_;
  r.world = world;
  r.paint = world->floor_layer();
  for (const std::string& name : r.settings.metric_names) r.MetricId(name);
  r.file->AddJson(static_cast<uint8_t>(ChunkKind::kHeader), 0, JsonText(r.Header()));
  r.WriteStep(*world);
}

void RunRecorder::Record(const World& world, std::vector<MetricSample>* out) {
  Impl& r = *impl_;
  const int64_t step = world.step_count();
  // The samples added since the last call: the scripts' of this step
  // (stamped with the step they ran in, one before this) and the
  // observers'. `out` holds what nobody has taken yet (the runner takes
  // them after every step; a binding may not).
  if (world.metrics_taken() != r.metrics_taken) {
    r.metrics_taken = world.metrics_taken();
    r.metrics_seen = 0;
  }
  for (size_t i = std::min(r.metrics_seen, out->size()); i < out->size(); ++i) {
    const MetricSample& m = (*out)[i];
    r.samples.push_back({r.MetricId(m.name), m.instance, static_cast<uint32_t>(m.step), m.value});
  }
  r.metrics_seen = out->size();
  // Every N steps, and the run's last: the viewer shows where it ended
  // (with every: 3, a 10-step run ended on step 9).
  if (step % r.settings.every != 0 && step != r.settings.steps_planned) return;
  r.WriteStep(world);
}

void RunRecorder::WriteOutputs(const std::filesystem::path& /*dir*/) const { impl_->file->Flush(); }

void RunRecorder::ListOutputs(std::vector<OutputFile>* out) const {
  // What the file holds (a full disk stops it short of the steps recorded).
  out->push_back(
      {"recording", kRecordingFileName,
       std::to_string(impl_->file->step_records_written()) + " step records (swarmsim view)"});
}

void RunRecorder::Finish(int64_t steps, const std::string& status, const std::string& error) {
  Impl& r = *impl_;
  if (r.finished) return;
  r.finished = true;
  // A run that ended before its world started (no thread for its watchdog)
  // wrote no header: an end chunk alone was a file no reader takes ("its
  // first chunk is no header"). No recording instead.
  if (r.world == nullptr) {
    std::error_code ec;
    std::filesystem::remove(r.settings.out_dir / kRecordingFileName, ec);
    return;
  }
  json j = {{"steps", steps}, {"status", status}};
  if (!error.empty()) j["error"] = error;
  try {
    r.file->AddJson(static_cast<uint8_t>(ChunkKind::kEnd), static_cast<uint32_t>(steps),
                    JsonText(j));
    r.file->Flush();
  } catch (const Error&) {
    // The steps before are all there; a viewer just does not learn that the run ended.
  }
}

int64_t RunRecorder::step_records() const { return impl_->records; }
uint64_t RunRecorder::bytes_written() const { return impl_->file->bytes_written(); }

std::string EncodeChunk(uint8_t kind, uint32_t step, const std::string& payload) {
  return EncodeChunkBytes(kind, step, payload);
}

RunRecorder* AddRecorder(World* world, const RecordSettings& settings) {
  auto recorder = std::make_unique<RunRecorder>(settings);
  RunRecorder* raw = recorder.get();
  world->AddObserver(std::move(recorder));
  return raw;
}

}  // namespace swarmsim::record
