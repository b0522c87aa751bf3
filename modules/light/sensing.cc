// Light sensors: what each reads of the lit light sources (light.h has the
// formula).
//
// Each sense phase:
// 1. the lit light sources (on, intensity > 0) are listed with their world
//    positions (a world has a few: every sensor tests every one);
// 2. the shapes the sensors' occlusion tests need, placed at their poses:
//    static ones (a shape of no robot that is not dynamic: walls,
//    obstacles) if a sensor has `occlusion`, moving ones (a robot's, or
//    dynamic) if one has `robot_occlusion`; each kind scanned whole when
//    there are few (a walled arena: 4 box tests), else put in a 2D grid
//    over its (x, y) bounds;
// 3. every sensor, in parallel (each writes only its own row): for each
//    light, but its own robot's, the distance and the angle off its +x
//    axis; a light out of range or outside the field of view adds nothing
//    and costs no occlusion test. Occlusion is tested on the segment from
//    the sensor's origin to the light's centre, stopping 1 um short of it
//    (the shape a light sits on does not hide it): the static shapes, the
//    moving ones (robot_occlusion; the grid's shapes along the segment, in
//    pieces about two cells long), each by its box and then the exact ray
//    test of modules/proximity; the shapes of the sensor's robot and of
//    the light's, or those either hangs from, never hide it. Then the
//    environment map's voxels, if the scene has a map (the world's line of
//    sight, framework/line_of_sight.h: a voxel walk along the segment).
//    The sum then gets the sensor's noise, drawn from the stream of
//    (the world's seed, the sensor's slot, the step, kLight): the same
//    readings whatever the thread count or row order.
#include <algorithm>
#include <cmath>

#include "framework/environment.h"
#include "framework/line_of_sight.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/sensor_noise.h"
#include "framework/world.h"
#include "modules/light/light.h"
#include "modules/light/module.h"

namespace swarmsim::light {

namespace {

constexpr double kPi = 3.141592653589793;
// The occlusion segment stops this short of the light (m).
constexpr double kEndMargin = 1e-6;
// A light nearer than this (m) counts as this near: the reading stays finite.
constexpr double kMinDistance = 1e-3;
// Sensors per task: a sensor costs tens of nanoseconds per light.
constexpr int64_t kSensorGrain = 256;
// Up to this many shapes of a kind, a segment tests them all (a box test
// each); more go into a grid.
constexpr size_t kScanLimit = 16;
// Robots per task of ClearRobots.
constexpr int64_t kRobotGrain = 64;

using proximity::Segment;

}  // namespace

void LightSensingModule::IndexSources(const Scene& scene) {
  sources_.clear();
  const Rows<LightSourceRow>& rows = scene.rows<LightSourceRow>(source_type_);
  for (size_t r = 0; r < rows.size(); ++r) {
    const LightSourceRow& l = rows.rows[r];
    if (!l.lit()) continue;
    const uint32_t slot = rows.owners[r];
    sources_.push_back(
        {scene.world_pose_at(slot).p, l.intensity, scene.instance_of_at(slot), slot});
  }
}

void LightSensingModule::IndexOccluders(const Scene& scene, bool static_shapes,
                                        bool moving_shapes) {
  static_.Clear();
  moving_.Clear();
  const auto shapes = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shapes.size(); ++r) {
    const uint32_t slot = owners[r];
    const int instance = scene.instance_of_at(slot);
    const bool moving = instance >= 0 || shapes[r].dynamic;
    if (!(moving ? moving_shapes : static_shapes)) continue;
    OccluderSet& set = moving ? moving_ : static_;
    Occluder& o = set.occluders.emplace_back();
    o.shape =
        proximity::PlaceShape(shapes[r], scene.world_pose_at(slot), scene.IdAt(slot), instance);
    o.slot = slot;
    proximity::WorldBounds(o.shape, &o.lo, &o.hi);
    // Grown a little: the exact test decides, these only must not miss.
    const double margin = 1e-9 * (1 + std::abs(o.lo.x) + std::abs(o.lo.y) + std::abs(o.lo.z) +
                                  std::abs(o.hi.x) + std::abs(o.hi.y) + std::abs(o.hi.z));
    o.lo = o.lo - Vec3{margin, margin, margin};
    o.hi = o.hi + Vec3{margin, margin, margin};
    set.z_lo = std::min(set.z_lo, o.lo.z);
    set.z_hi = std::max(set.z_hi, o.hi.z);
    set.items.push_back({0.5 * (o.lo.x + o.hi.x), 0.5 * (o.lo.y + o.hi.y),
                         0.5 * std::hypot(o.hi.x - o.lo.x, o.hi.y - o.lo.y),
                         static_cast<uint32_t>(set.items.size())});
  }
  for (OccluderSet* set : {&static_, &moving_}) {
    set->use_grid = set->occluders.size() > kScanLimit;
    if (set->use_grid) set->grid.Build(set->items);
  }
}

bool LightSensingModule::Hidden(const Scene& scene, const OccluderSet& set, const Vec3& p_W,
                                const Vec3& q_W, int sensor_instance, uint32_t sensor_slot,
                                const LitSource& source) const {
  if (set.occluders.empty()) return false;
  const Vec3 v_W = q_W - p_W;
  const double length = v_W.Norm();
  if (!(length > 0)) return false;
  const Vec3 d_W = v_W / length;
  const Segment segment(p_W, v_W);
  // One shape: its box first (most miss it); skipped when it is the
  // sensor's robot's or the light's (a robot's own light shines through
  // its body, as ARGoS has it), or one either hangs from; then the exact
  // ray test.
  const auto hides = [&](const Occluder& o) {
    if (!segment.MeetsBox(o.lo, o.hi)) return false;
    const int owner = o.shape.instance;
    if (owner >= 0 ? owner == sensor_instance || owner == source.instance
                   : scene.IsAbove(o.slot, sensor_slot) || scene.IsAbove(o.slot, source.slot))
      return false;
    double hit = 0;
    return proximity::RayCast(o.shape, p_W, d_W, length, &hit);
  };
  if (!set.use_grid) {
    for (const Occluder& o : set.occluders)
      if (hides(o)) return true;
    return false;
  }
  // Only the part of the segment at the shapes' heights can meet one (a
  // lamp high above the robots: the few centimetres next to the sensor).
  double t0 = 0, t1 = 1;
  if (v_W.z != 0) {
    double ta = (set.z_lo - p_W.z) / v_W.z, tb = (set.z_hi - p_W.z) / v_W.z;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    if (!(t0 <= t1)) return false;
  } else if (p_W.z < set.z_lo || p_W.z > set.z_hi) {
    return false;
  }
  // That part in pieces about two cells long, each piece's box asked of the
  // grid: the shapes listed stay near the segment however long it is. A
  // shape listed twice (near a piece's end) is only tested twice.
  const double piece = 2 * set.grid.cell_size();
  const int pieces =
      std::clamp(static_cast<int>((t1 - t0) * std::hypot(v_W.x, v_W.y) / piece) + 1, 1, 1 << 16);
  thread_local std::vector<uint32_t> near;
  for (int k = 0; k < pieces; ++k) {
    const Vec3 a = p_W + v_W * (t0 + (t1 - t0) * k / pieces);
    const Vec3 b = p_W + v_W * (t0 + (t1 - t0) * (k + 1) / pieces);
    set.grid.QueryAabb(
        {std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)}, &near);
    for (const uint32_t j : near)
      if (hides(set.occluders[j])) return true;
  }
  return false;
}

void LightSensingModule::ClearRobots(World* world, const Rows<LightSensorRow>& sensors) {
  const Scene& scene = world->scene();
  const size_t robots = scene.instances().size(), lights = sources_.size();
  reach_.assign(robots, -1);
  roots_.resize(robots);
  for (size_t r = 0; r < sensors.size(); ++r) {
    const uint32_t slot = sensors.owners[r];
    const int i = scene.instance_of_at(slot);
    if (i < 0 || !sensors.rows[r].settings->occlusion) continue;
    if (reach_[i] < 0) roots_[i] = scene.world_pose(scene.instances()[i].root).p;
    reach_[i] = std::max(reach_[i], (scene.world_pose_at(slot).p - roots_[i]).Norm());
  }
  robot_clear_.assign(robots * lights, 0);
  world->scheduler().ParallelFor(0, static_cast<int64_t>(robots), kRobotGrain,
                                 [&](int64_t begin, int64_t end) {
                                   for (int64_t i = begin; i < end; ++i) {
                                     const double reach = reach_[i];
                                     if (reach < 0) continue;
                                     const Vec3& root = roots_[i];
                                     // Grown a little more than the reach, for rounding.
                                     const double grow = reach * (1 + 1e-9) + 1e-9;
                                     const Vec3 g{grow, grow, grow};
                                     for (size_t l = 0; l < lights; ++l) {
                                       const Segment segment(root, sources_[l].p_W - root);
                                       bool clear = true;
                                       for (const Occluder& o : static_.occluders)
                                         if (segment.MeetsBox(o.lo - g, o.hi + g)) {
                                           clear = false;
                                           break;
                                         }
                                       robot_clear_[static_cast<size_t>(i) * lights + l] = clear;
                                     }
                                   }
                                 });
}

void LightSensingModule::Read(const Scene& scene, uint32_t slot, LightSensorRow* sensor) const {
  const LightSensorSettings& s = *sensor->settings;
  const Pose& X_WS = scene.world_pose_at(slot);
  const Vec3& p_W = X_WS.p;
  const Vec3 axis_W = X_WS.q.Rotate({1, 0, 0});
  const int instance = scene.instance_of_at(slot);
  const double half_fov = 0.5 * s.fov;
  const bool narrow = half_fov <= 0.5 * kPi;
  const double range2 = s.range > 0 ? s.range * s.range : INFINITY;
  double sum = 0;
  const uint8_t* clear = instance >= 0 && !robot_clear_.empty()
                             ? &robot_clear_[static_cast<size_t>(instance) * sources_.size()]
                             : nullptr;
  for (size_t l = 0; l < sources_.size(); ++l) {
    const LitSource& light = sources_[l];
    if (instance >= 0 && light.instance == instance) continue;  // its own robot's
    const Vec3 d_W = light.p_W - p_W;
    const double d2 = d_W.SquaredNorm();
    if (!(d2 <= range2)) continue;
    const double dot = axis_W.Dot(d_W);
    if (narrow && !(dot > 0)) continue;  // behind a field of view of 180 deg or less
    const double d = std::sqrt(d2);
    // The angle off the axis; a light at the sensor's origin is on it.
    const double c = d > 0 ? std::clamp(dot / d, -1.0, 1.0) : 1.0;
    const double theta = std::acos(c);
    if (!(theta < half_fov)) continue;
    const double response = 1 - theta / half_fov;
    // Occlusion: the cheaper static test first.
    if (s.occlusion || s.robot_occlusion) {
      const double length = d - kEndMargin;
      if (length > 0) {
        const Vec3 end = p_W + d_W * (length / d);
        if (s.occlusion && !(clear != nullptr && clear[l]) &&
            Hidden(scene, static_, p_W, end, instance, slot, light))
          continue;
        if (s.robot_occlusion && Hidden(scene, moving_, p_W, end, instance, slot, light)) continue;
        if (s.occlusion && map_ != nullptr && map_->SegmentBlocked(p_W, end)) continue;
      }
    }
    const double dm = std::max(d, kMinDistance);
    sum += light.intensity * response / (dm * dm);
  }
  if (s.noise.any()) {
    Rng rng = NoiseStream(seed_, slot, step_, NoisePurpose::kLight);
    sum = Fails(s.noise, rng) ? 0 : std::max(0.0, Perturb(s.noise, sum, rng));
  }
  if (s.saturation > 0) sum = std::min(sum, s.saturation);
  sensor->reading = sum;
}

void LightSensingModule::Sense(World* world) {
  Scene& scene = world->scene();
  if (!types_found_) {
    have_types_ = scene.FindType(kLightSourceTypeName, &source_type_) &&
                  scene.FindType(kLightSensorTypeName, &sensor_type_);
    types_found_ = true;
  }
  if (!have_types_) return;
  Rows<LightSensorRow>& sensors = scene.rows<LightSensorRow>(sensor_type_);
  if (sensors.size() == 0) return;
  seed_ = world->settings().seed;
  step_ = world->step_count();
  const EnvironmentMap* map = scene.environment();
  map_ = map != nullptr && !map->boxes.empty() ? world->line_of_sight() : nullptr;
  IndexSources(scene);
  // The shapes only the sensors that test them need.
  bool static_shapes = false, moving_shapes = false;
  if (!sources_.empty())
    for (const LightSensorRow& row : sensors.rows) {
      static_shapes = static_shapes || row.settings->occlusion;
      moving_shapes = moving_shapes || row.settings->robot_occlusion;
      if (static_shapes && moving_shapes) break;
    }
  static_.Clear();
  moving_.Clear();
  if (static_shapes || moving_shapes) IndexOccluders(scene, static_shapes, moving_shapes);
  // Robots far from every static shape skip them (a few shapes only: many
  // are in a grid, which each segment asks).
  robot_clear_.clear();
  if (!static_.occluders.empty() && !static_.use_grid) ClearRobots(world, sensors);
  world->scheduler().ParallelFor(0, static_cast<int64_t>(sensors.size()), kSensorGrain,
                                 [&](int64_t begin, int64_t end) {
                                   for (int64_t r = begin; r < end; ++r)
                                     Read(scene, sensors.owners[r], &sensors.rows[r]);
                                 });
}

}  // namespace swarmsim::light
