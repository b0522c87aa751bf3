#include "modules/rendering/module.h"

#include <algorithm>
#include <cmath>

#include "framework/collections.h"
#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/rendering/objects.h"
#include "modules/rendering/render.h"

namespace swarmsim::rendering {

namespace {

constexpr int kSensorSegments = 16;  // sides of cylinders, slices of spheres

// Level of detail: sides of a cylinder for an image `width` pixels wide (a
// 64-pixel image gets octagons; nobody sees the difference, and it is half
// the triangles of 16).
int SegmentsFor(int width) { return std::clamp(width / 8, 8, 24); }

Rows<VisionSensorRow>* Sensors(Scene* scene) {
  ObjectType type;
  if (!scene->FindType("vision_sensor", &type)) return nullptr;
  return static_cast<Rows<VisionSensorRow>*>(scene->rows(type));
}

// Steps between two images of a sensor at `rate` Hz.
int64_t Period(double rate, double time_step) {
  if (rate <= 0) return 1;
  return std::max<int64_t>(1, std::llround(1 / (rate * time_step)));
}

}  // namespace

View ViewOf(const Scene& scene, uint32_t slot, const Lens& lens, bool depth) {
  View v;
  v.pose = scene.world_pose_at(slot);
  v.orthographic = lens.orthographic;
  v.fov = lens.fov;
  v.ortho_width = lens.ortho_width;
  v.near = lens.near;
  v.far = lens.far;
  v.width = lens.width;
  v.height = lens.height;
  v.depth = depth;
  return v;
}

bool RenderingModule::SaveState(const World& world, StateWriter*) const {
  const Scene& scene = world.scene();
  for (const char* name : {"vision_sensor", "camera"}) {
    ObjectType type;
    if (scene.FindType(name, &type) && scene.rows(type) != nullptr && scene.rows(type)->size() > 0)
      return false;
  }
  return true;
}

void RenderingModule::Start(World* world) { RenderDue(world, /*all=*/true); }

void RenderingModule::Sense(World* world) { RenderDue(world, /*all=*/false); }

void RenderingModule::RenderDue(World* world, bool all) {
  Scene& scene = world->scene();
  Rows<VisionSensorRow>* sensors = Sensors(&scene);
  if (sensors == nullptr || sensors->size() == 0) return;
  const int64_t step = world->step_count();
  std::vector<uint32_t> due;
  for (uint32_t r = 0; r < sensors->size(); ++r) {
    const VisionSensorRow& s = sensors->rows[r];
    if (!scene.alive_at(sensors->owners[r])) continue;
    if (all || s.rendered_step < 0 || step % Period(s.rate, world->settings().time_step) == 0)
      due.push_back(r);
  }
  if (due.empty()) return;
  // The detectable sets, when the scene's structure changed.
  if (version_ != scene.structure_version()) {
    visible_.assign(sensors->size(), {});
    for (uint32_t r = 0; r < sensors->size(); ++r) {
      const VisionSensorRow& s = sensors->rows[r];
      if (s.detectable.empty()) continue;
      const ObjectId id = scene.IdAt(sensors->owners[r]);
      std::vector<uint8_t>& mask = visible_[r];
      mask.assign(scene.slot_count(), 0);
      for (uint32_t slot : EntitySlots(scene, ParseEntity(s.detectable).path, id,
                                       (s.where.empty() ? "" : s.where + ": ") + "vision sensor " +
                                           scene.PathOf(id) + " ('detectable')",
                                       Missing::kNone))
        mask[slot] = 1;
    }
    version_ = scene.structure_version();
  }
  // Each list the due sensors need, built once (then pointed at: the vector
  // no longer grows).
  std::vector<int> segments_of(due.size());
  std::vector<int> built;
  for (size_t i = 0; i < due.size(); ++i) {
    const int segments = SegmentsFor(sensors->rows[due[i]].lens.width);
    segments_of[i] = segments;
    if (std::find(built.begin(), built.end(), segments) != built.end()) continue;
    built.push_back(segments);
    auto it = std::find_if(lists_.begin(), lists_.end(),
                           [&](const auto& entry) { return entry.first == segments; });
    if (it == lists_.end()) it = lists_.insert(lists_.end(), {segments, DrawList{}});
    BuildDrawList(*world, segments, &it->second);
  }
  std::vector<const DrawList*> list_of(due.size());
  for (size_t i = 0; i < due.size(); ++i)
    for (const auto& [segments, list] : lists_)
      if (segments == segments_of[i]) list_of[i] = &list;
  world->scheduler().ParallelFor(
      0, static_cast<int64_t>(due.size()), 1, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          const uint32_t r = due[i];
          VisionSensorRow& s = sensors->rows[r];
          DrawOptions options;
          options.visible = visible_[r].empty() ? nullptr : &visible_[r];
          options.floor = s.floor;
          options.background = s.background;
          Draw(*list_of[i], ViewOf(scene, sensors->owners[r], s.lens, s.depth), options, &s.image);
          // Packet 1 is left to sim.readVisionSensor (most runs never read it).
          if (!s.filters.empty())
            s.filters.Run(s.image, CameraModelOf(s.lens), &s.output, /*statistics=*/false);
          s.rendered_step = step;
        }
      });
}

ModuleDescriptor RenderingModuleDescriptor() {
  return {{"sensing", kModuleName, "1.0",
           "cameras, lights and vision sensors drawn with Mesa's off-screen OpenGL (OSMesa)"},
          PhaseBit(Phase::kSense),
          150,
          /*every_world=*/true,
          [](World*, const void*) { return std::make_unique<RenderingModule>(); }};
}

// --- render.h ---------------------------------------------------------------------------

void Render(const World& world, const View& view, Image* image) {
  DrawList list;
  // A view from above keeps LEDs at least 3 pixels across.
  const double pixel = view.orthographic ? view.ortho_width / std::max(1, view.width) : 0;
  BuildDrawList(world, kSensorSegments, &list, 1.5 * pixel);
  Draw(list, view, DrawOptions{}, image);
}

View ArenaView(const World& world, int width, int height) {
  DrawList list;
  BuildDrawList(world, 4, &list);
  Vec3 lo = list.lo, hi = list.hi;
  if (list.floor.present) {
    lo = {std::min(lo.x, list.floor.min_x), std::min(lo.y, list.floor.min_y), lo.z};
    hi = {std::max(hi.x, list.floor.max_x), std::max(hi.y, list.floor.max_y), hi.z};
  }
  if (!(hi.x > lo.x) || !(hi.y > lo.y)) {
    lo = {-1, -1, 0};
    hi = {1, 1, 1};
  }
  const double margin = 0.05 * std::max(hi.x - lo.x, hi.y - lo.y);
  const double w = hi.x - lo.x + 2 * margin, h = hi.y - lo.y + 2 * margin;
  View v;
  v.orthographic = true;
  v.width = width;
  v.height = height;
  // The image's width spans x, its height y (north up): wide enough for both.
  v.ortho_width = std::max(w, h * width / std::max(1, height));
  const double top = std::max(hi.z, 0.0) + 1;
  v.near = 0.01;
  v.far = top - std::min(lo.z, 0.0) + 1;
  // Looking down (+x to -z), image up = +y: pitch down 90 degrees, then yaw 90.
  v.pose.p = {(lo.x + hi.x) / 2, (lo.y + hi.y) / 2, top};
  v.pose.q = Quat::FromYaw(M_PI / 2) * Quat::FromAxisAngle({0, 1, 0}, M_PI / 2);
  return v;
}

std::optional<View> CameraView(const World& world, std::string_view path, std::string* error) {
  const Scene& scene = world.scene();
  const ObjectId id = scene.FindObject(path);
  if (id.IsNull()) {
    *error = scene.ExplainMissingPath(path);
    return std::nullopt;
  }
  const uint32_t slot = scene.SlotOf(id);
  ObjectType camera, sensor;
  if (scene.FindType("camera", &camera) && scene.type_at(slot) == camera) {
    const auto& rows = static_cast<const Rows<CameraRow>&>(*scene.rows(camera));
    return ViewOf(scene, slot, rows.rows[scene.row_at(slot)].lens, false);
  }
  if (scene.FindType("vision_sensor", &sensor) && scene.type_at(slot) == sensor) {
    const auto& rows = static_cast<const Rows<VisionSensorRow>&>(*scene.rows(sensor));
    return ViewOf(scene, slot, rows.rows[scene.row_at(slot)].lens, false);
  }
  std::string message = "'";
  message += path;
  message += "' is a ";
  message += scene.type_name(scene.type_at(slot));
  message += ", not a camera or vision sensor";
  *error = std::move(message);
  return std::nullopt;
}

}  // namespace swarmsim::rendering
