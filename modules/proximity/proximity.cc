// The proximity backend: ray sensors against the static environment (an
// OctoMap octree built once, see static_index.h) and against robots and
// dynamic shapes (a grid of their footprints rebuilt every step); volume
// and randomized-ray sensors (volume.h) one by one against the shapes whose
// bounds meet their volume's box (SenseVolume, at the end).
//
// Detection rules:
// - A ray sensor is a ray from its origin along its +z axis, of length `range`.
// - The nearest exact hit wins; on an exact tie the static environment wins,
//   then the lower shape row (deterministic).
// - A ray that starts inside or on a shape hits it at distance 0.
// - A robot's sensors never see that robot's own shapes; a sensor that
//   belongs to no robot never sees the shapes it is mounted on (its ancestors).
// - Static shapes (no robot, not dynamic) are frozen at Build(): moving one
//   later, or adding one, is not seen. Make such a shape dynamic or part of
//   a model if it moves.
//
// The early-out. Most robots of a swarm have nothing within reach, and each
// of their rays would find nothing. CastAll() is the reference: every ray
// built and cast, with one static test (StaticIndex::AnyOccupied) and one
// grid query per robot. SenseBatch() writes the same bits, skipping only
// work whose result is known to be "nothing":
// - The box that grows each sensor's origin by its range (and by a margin
//   far above rounding) holds every ray segment. If the static index's
//   coarse map has nothing in it and the footprint grid no other robot's
//   shape, every ray reads "nothing" without being built.
// - Otherwise a ray is built and cast only if its own box (of its segment,
//   or of its origin's ball) meets another robot's footprint or holds an
//   occupied voxel: a static cast walks only voxels along its segment and
//   tests shapes only in occupied ones.
// Every test is conservative and only grows with the box.
#include "modules/proximity/proximity.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "framework/prefault.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/footprint_grid.h"
#include "modules/proximity/proximity_sensor.h"
#include "modules/proximity/ray_cast.h"
#include "modules/proximity/static_follower.h"
#include "modules/proximity/static_index.h"
#include "modules/proximity/volume.h"

namespace swarmsim::proximity {
namespace {

struct SensorRay {  // 64 bytes
  Vec3 p_W;         // ray origin in the world
  Vec3 d_W;         // unit direction in the world
  double range;     // m
  uint32_t row;     // row in the proximity sensors' table
};

struct SensorRef {  // 8 bytes
  uint32_t slot;    // the sensor object
  uint32_t row;     // its row in the proximity sensors' table
};

SensorRay MakeRay(const Scene& scene, std::span<const ProximitySensorData> readings,
                  uint32_t slot) {
  const Pose& X_WS = scene.world_pose_at(slot);
  const uint32_t row = scene.row_at(slot);
  Vec3 d = X_WS.q.Rotate({0, 0, 1});
  // Unit already unless the pose's quaternion drifted; skip the sqrt then.
  const double norm2 = d.SquaredNorm();
  if (std::abs(norm2 - 1) > 1e-14 && norm2 > 0) d = d / std::sqrt(norm2);
  return {X_WS.p, d, readings[row].range(), row};
}

// The rays of `sensors`, in order (written field by field: copying a fresh
// SensorRay whole stalls on store forwarding).
void MakeRays(const Scene& scene, std::span<const ProximitySensorData> readings,
              std::span<const SensorRef> sensors, std::vector<SensorRay>* rays) {
  rays->resize(sensors.size());
  for (size_t i = 0; i < sensors.size(); ++i) {
    const SensorRay ray = MakeRay(scene, readings, sensors[i].slot);
    SensorRay& out = (*rays)[i];
    out.p_W.x = ray.p_W.x, out.p_W.y = ray.p_W.y, out.p_W.z = ray.p_W.z;
    out.d_W.x = ray.d_W.x, out.d_W.y = ray.d_W.y, out.d_W.z = ray.d_W.z;
    out.range = ray.range, out.row = ray.row;
  }
}

// The reading of a ray that found nothing.
void ReadNothing(ProximitySensorData* reading) {
  reading->detected = false;
  reading->distance = 0;
  reading->detected_object = ObjectId{};
}

// Zero if and only if the reading is ReadNothing's, bit for bit.
uint64_t NothingBits(const ProximitySensorData& reading) {
  return uint64_t{reading.detected} | std::bit_cast<uint64_t>(reading.distance) |
         std::bit_cast<uint64_t>(reading.detected_object);
}

class OctreeGridProximity final : public ProximityBackend {
 public:
  explicit OctreeGridProximity(const BackendOptions& options) : options_(options) {}

  void Build(const Scene& scene, const ProximitySettings& settings) override {
    have_sensor_type_ = FindSensorType(scene, &sensor_type_);
    resolution_ = settings.octree_resolution;
    seed_ = settings.seed;
    scheduler_ = settings.scheduler;
    IndexStatic(scene);
    follower_.PlaceMoved(scene);
    Update(scene);
  }

  void FollowStaticShapes(const Scene& scene) override {
    if (follower_.Follow(scene)) IndexStatic(scene);
    follower_.PlaceMoved(scene);
  }

  // Places every robot shape and dynamic shape and rebuilds the grid over
  // their footprints. Buffers keep their capacity: no allocation once warm.
  // The shapes are placed on every thread, in blocks of shape rows whose
  // places in the arrays a first pass counts: the same arrays, in shape row
  // order, for any thread count.
  void Update(const Scene& scene) override {
    // (A Scene made without a World gets the type with its first sensor.)
    if (!have_sensor_type_) have_sensor_type_ = FindSensorType(scene, &sensor_type_);
    const auto shapes = scene.shapes();
    const auto owners = scene.shape_owners();
    const size_t rows = shapes.size();
    // Moving: a robot's shape, a dynamic one, or a static one that moved.
    const auto moving = [&](size_t r) {
      return shapes[r].dynamic || scene.instance_of_at(owners[r]) >= 0 ||
             follower_.IsMoved(owners[r]);
    };
    const size_t blocks = (rows + kPlaceBlock - 1) / kPlaceBlock;
    block_start_.assign(blocks + 1, 0);
    ForEachBlock(blocks, [&](size_t b) {
      uint32_t count = 0;
      for (size_t r = b * kPlaceBlock; r < std::min(rows, (b + 1) * kPlaceBlock); ++r)
        count += moving(r) ? 1 : 0;
      block_start_[b + 1] = count;
    });
    for (size_t b = 0; b < blocks; ++b) block_start_[b + 1] += block_start_[b];
    const size_t placed = block_start_[blocks];
    // At most one entry per shape: the first Update sizes every buffer for
    // the whole swarm at once, leaving no slack from growing one by one.
    if (moving_.capacity() < placed || footprint_memos_.capacity() < rows) {
      moving_.clear();
      footprints_.clear();
      squares_.clear();
      instances_.clear();
      ids_.clear();
      const size_t n = std::max(rows, 2 * moving_.capacity());
      // A large swarm's buffers are fresh pages: populated on every thread.
      Prefault prefault;
      prefault.Reserve(moving_, n);
      prefault.Reserve(footprints_, n);
      prefault.Reserve(squares_, n);
      prefault.Reserve(instances_, n);
      prefault.Reserve(ids_, n);
      prefault.Reserve(footprint_memos_, n);  // the memos are kept
      if (scheduler_ != nullptr) prefault.Run(*scheduler_);
    }
    footprint_memos_.resize(rows);
    moving_.resize(placed);
    footprints_.resize(placed);
    squares_.resize(placed);
    instances_.resize(placed);
    ids_.resize(placed);
    ForEachBlock(blocks, [&](size_t b) {
      uint32_t index = block_start_[b];
      const size_t end = std::min(rows, (b + 1) * kPlaceBlock);
      for (size_t r = b * kPlaceBlock; r < end; ++r) {
        // The poses of a big swarm outgrow the cache, and shape rows stride
        // through them: ask for one a few rows ahead.
        constexpr size_t kAhead = 8;
        if (r + kAhead < end) __builtin_prefetch(&scene.world_pose_at(owners[r + kAhead]));
        if (!moving(r)) continue;
        const uint32_t slot = owners[r];
        const int instance = scene.instance_of_at(slot);
        const Pose& X_WS = scene.world_pose_at(slot);
        const ObjectId id = scene.IdAt(slot);
        const double x = X_WS.p.x, y = X_WS.p.y;
        const double radius = WorldFootprintRadius(shapes[r], X_WS, &footprint_memos_[r]);
        footprints_[index] = {x, y, radius, index};
        // Its bounding square, grown by the margin (the rounding of the exact
        // tests is relative to the footprint's coordinates too).
        const double half = radius + kReachMargin * (std::abs(x) + std::abs(y) + radius);
        squares_[index] = {x - half, y - half, x + half, y + half};
        instances_[index] = instance;
        ids_[index] = id;
        moving_[index] = PlaceShape(shapes[r], X_WS, id, instance);
        ++index;
      }
    });
    // The early-out's own broad phase, or (casting every ray) the spatial grid.
    if (options_.early_out) {
      footprint_grid_.Build(squares_, instances_, ids_, scheduler_);
    } else {
      grid_.Build(footprints_);
    }
    if (have_sensor_type_ && !SensorListsCurrent(scene)) ListSensors(scene);
  }

  void SetStep(uint64_t step) override { step_ = step; }
  void SetDetectableFilter(DetectableFilter filter) override { detectable_ = std::move(filter); }

  void SenseInstance(Scene* scene, int instance) const override {
    if (!have_sensor_type_) return;  // no proximity sensor anywhere
    if (SensorListsCurrent(*scene)) {
      const size_t i = static_cast<size_t>(instance);
      SenseBatch({instance_sensors_.data() + instance_sensor_start_[i],
                  instance_sensors_.data() + instance_sensor_start_[i + 1]},
                 instance, {}, scene);
      for (uint32_t k = instance_volume_start_[i]; k < instance_volume_start_[i + 1]; ++k)
        SenseVolume(instance_volumes_[k], instance, {}, scene);
      return;
    }
    // The scene changed since Update(): find the sensors the slow way.
    thread_local std::vector<SensorRef> sensors, volumes;
    sensors.clear();
    volumes.clear();
    for (uint32_t slot : scene->instance(instance).objects)
      if (scene->type_at(slot) == sensor_type_)
        (IsRay(*scene, slot) ? sensors : volumes).push_back({slot, scene->row_at(slot)});
    SenseBatch(sensors, instance, {}, scene);
    for (const SensorRef& sensor : volumes) SenseVolume(sensor, instance, {}, scene);
  }

  bool SegmentBlocked(const Vec3& a_W, const Vec3& b_W) const override {
    const Vec3 d = b_W - a_W;
    const double length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (!(length > 0)) return false;
    const Vec3 d_W = d * (1 / length);
    double t = 0;
    uint32_t shape = 0;
    if (!static_.empty() && static_.CastRay(a_W, d_W, length, {}, &t, &shape)) return true;
    return follower_.LineBlocked(a_W, d_W, length);
  }

  void SenseSceneSensors(Scene* scene) const override {
    if (!have_sensor_type_) return;
    if (SensorListsCurrent(*scene)) {
      for (const SensorRef& sensor : scene_sensors_) SenseSceneSensor(sensor, scene);
      return;
    }
    const std::span<const uint32_t> owners = Table(*scene).owners;
    for (size_t row = 0; row < owners.size(); ++row)
      if (scene->instance_of_at(owners[row]) < 0)
        SenseSceneSensor({owners[row], static_cast<uint32_t>(row)}, scene);
  }

 private:
  // The static index of the static shapes but those known to move, and
  // their bounds.
  void IndexStatic(const Scene& scene) {
    static_.Build(scene, resolution_, follower_.moved());
    static_lo_.clear();
    static_hi_.clear();
    for (const PlacedShape& shape : static_.shapes()) {
      Vec3 lo, hi;
      WorldBounds(shape, &lo, &hi);
      static_lo_.push_back(lo);
      static_hi_.push_back(hi);
    }
    follower_.Indexed(scene, static_);
  }

  // Are the sensor lists of ListSensors() those of the scene as it is now?
  // Every change that adds, removes or moves a sensor between robots bumps
  // the structure version or adds an instance.
  bool SensorListsCurrent(const Scene& scene) const {
    return listed_version_ == scene.structure_version() &&
           listed_instances_ == scene.instances().size();
  }

  // The proximity sensors' rows (the type FindSensorType gave).
  Rows<ProximitySensorData>& Table(Scene* scene) const {
    return scene->rows<ProximitySensorData>(sensor_type_);
  }
  const Rows<ProximitySensorData>& Table(const Scene& scene) const {
    return scene.rows<ProximitySensorData>(sensor_type_);
  }

  // A ray sensor (the batched fast path), or a volume or randomized rays?
  bool IsRay(const Scene& scene, uint32_t slot) const {
    return Table(scene).rows[scene.row_at(slot)].volume() == ProximityVolume::kRay;
  }

  // Lists each robot's sensors (hierarchy order; rays apart from volumes)
  // and the sensors of no robot.
  void ListSensors(const Scene& scene) {
    const auto& instances = scene.instances();
    instance_sensor_start_.assign(1, 0);
    instance_sensors_.clear();
    instance_volume_start_.assign(1, 0);
    instance_volumes_.clear();
    for (const ModelInstance& instance : instances) {
      for (uint32_t slot : instance.objects)
        if (scene.type_at(slot) == sensor_type_)
          (IsRay(scene, slot) ? instance_sensors_ : instance_volumes_)
              .push_back({slot, scene.row_at(slot)});
      instance_sensor_start_.push_back(static_cast<uint32_t>(instance_sensors_.size()));
      instance_volume_start_.push_back(static_cast<uint32_t>(instance_volumes_.size()));
    }
    scene_sensors_.clear();
    const std::span<const uint32_t> owners = Table(scene).owners;
    for (size_t row = 0; row < owners.size(); ++row)
      if (scene.instance_of_at(owners[row]) < 0)
        scene_sensors_.push_back({owners[row], static_cast<uint32_t>(row)});
    listed_version_ = scene.structure_version();
    listed_instances_ = instances.size();
  }

  void SenseSceneSensor(const SensorRef& sensor, Scene* scene) const {
    thread_local std::vector<ObjectId> mounts;
    // The shapes the sensor hangs from are not obstacles to it.
    mounts.clear();
    for (int32_t a = scene->parent_at(sensor.slot); a >= 0; a = scene->parent_at(a))
      if (scene->type_at(a) == ObjectType::kShape) mounts.push_back(scene->IdAt(a));
    if (IsRay(*scene, sensor.slot)) return SenseBatch({&sensor, 1}, -1, mounts, scene);
    SenseVolume(sensor, -1, mounts, scene);
  }

  // Reads the sensors of one robot (`instance`, or -1 for a scene sensor):
  // the same readings as CastAll, casting only the rays that may see
  // something.
  void SenseBatch(std::span<const SensorRef> sensors, int instance, std::span<const ObjectId> skip,
                  Scene* scene) const {
    if (sensors.empty()) return;
    if (!options_.early_out) return CastAll(sensors, instance, skip, scene);
    // The box of all the sensors' reach: their origins' box grown by the
    // longest range and the margin. Stand aside (cast) if an origin or a
    // range is not finite, or a quaternion is so far from unit (|q|^2 >
    // 2e307) that MakeRay's rotation could overflow: then `sum` is not finite.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo_x = kInf, lo_y = kInf, lo_z = kInf, hi_x = -kInf, hi_y = -kInf, hi_z = -kInf;
    double longest = 0, sum = 0;
    uint64_t written = 0;  // zero if every reading already reads "nothing"
    const std::span<ProximitySensorData> readings = Table(scene).rows;
    for (const SensorRef& sensor : sensors) {
      const Pose& X_WS = scene->world_pose_at(sensor.slot);
      const double x = X_WS.p.x, y = X_WS.p.y, z = X_WS.p.z;
      const ProximitySensorData& reading = readings[sensor.row];
      const double range = reading.range();
      lo_x = std::min(lo_x, x), lo_y = std::min(lo_y, y), lo_z = std::min(lo_z, z);
      hi_x = std::max(hi_x, x), hi_y = std::max(hi_y, y), hi_z = std::max(hi_z, z);
      longest = std::max(longest, range);
      const Quat& q = X_WS.q;
      sum += ((x + y) + (z + range)) + 4 * ((q.w * q.w + q.x * q.x) + (q.y * q.y + q.z * q.z));
      written |= NothingBits(reading);
    }
    if (!std::isfinite(sum)) return CastAll(sensors, instance, skip, scene);
    // margin: at least kReachMargin (range + |p|_1) for every sensor.
    const double margin =
        kReachMargin * (longest + std::abs(lo_x) + std::abs(lo_y) + std::abs(lo_z) +
                        std::abs(hi_x) + std::abs(hi_y) + std::abs(hi_z));
    const double reach = longest + margin;
    const Vec3 lo{lo_x - reach, lo_y - reach, lo_z - reach};
    const Vec3 hi{hi_x + reach, hi_y + reach, hi_z + reach};
    // It holds CastAll's batch box, and both tests only grow with the box:
    // if neither finds anything, CastAll finds nothing for any ray.
    bool near_static = static_.MayBeOccupied(lo, hi);
    const Aabb2 box{lo.x, lo.y, hi.x, hi.y};
    const bool near_robot = footprint_grid_.AnyOther(box, instance, skip);
    if (!near_static && !near_robot) {
      if (written != 0)
        for (const SensorRef& sensor : sensors) ReadNothing(&readings[sensor.row]);
      return;
    }
    // The other robots' shapes near the batch, with their footprints' squares.
    thread_local std::vector<uint32_t> candidates;
    thread_local std::vector<Aabb2> squares;
    candidates.clear();
    squares.clear();
    if (near_robot) {
      Candidates(box, instance, skip, &candidates);
      for (uint32_t c : candidates) squares.push_back(squares_[c]);
    }
    // Near a wall: CastAll's own test, on its exact batch box, decides
    // whether rays are cast against the static index at all.
    thread_local std::vector<SensorRay> rays;
    rays.clear();
    if (near_static) {
      MakeRays(*scene, readings, sensors, &rays);
      Vec3 ray_lo, ray_hi;
      RayBounds(rays, &ray_lo, &ray_hi);
      near_static = AnyOccupied(ray_lo, ray_hi);
    }
    for (size_t i = 0; i < sensors.size(); ++i) {
      const SensorRef& sensor = sensors[i];
      // The ray's box: of its segment if built, else of the ball of radius
      // range about its origin (range >= 0 and |d| <= 1 + 1e-14 make the
      // segment lie in it); grown by at least the margin.
      Vec3 a, b;
      if (!rays.empty()) {
        SegmentBox(rays[i], &a, &b);
      } else {
        const Vec3& p = scene->world_pose_at(sensor.slot).p;
        const double range = readings[sensor.row].range();
        const double r = (range > 0 ? range : 0) + margin;
        a = {p.x - r, p.y - r, p.z - r};
        b = {p.x + r, p.y + r, p.z + r};
      }
      // A static cast walks only voxels within the ray's segment box (grown
      // by a rounding margin), testing shapes only in occupied ones: with no
      // occupied voxel there it finds nothing. (A non-finite direction: cast.
      // Where the coarse map is not exact, the cast itself skips the rest.)
      const bool static_in_reach =
          near_static && (!FiniteDirection(rays[i]) || static_.MayBeOccupied(a, b));
      // Another robot's shape is tested only if its footprint meets the
      // ray's box; then the footprint's square meets this bigger one (the
      // margin covers the rounding of both tests).
      const bool robot_in_reach = std::any_of(squares.begin(), squares.end(), [&](const Aabb2& q) {
        return q.max_x >= a.x && q.min_x <= b.x && q.max_y >= a.y && q.min_y <= b.y;
      });
      if (!static_in_reach && !robot_in_reach) {
        ReadNothing(&readings[sensor.row]);
        continue;
      }
      SenseRay(rays.empty() ? MakeRay(*scene, readings, sensor.slot) : rays[i], static_in_reach,
               candidates, skip, scene);
    }
  }

  // Margin, relative to the coordinates and the range, by which the boxes of
  // the early-out exceed the rays: far above rounding (1e-16 relative per
  // operation, 1e-11 over the longest voxel walk) and far below what a robot
  // would notice.
  static constexpr double kReachMargin = 1e-7;

  // StaticIndex::AnyOccupied, asking the coarse map first.
  bool AnyOccupied(const Vec3& lo, const Vec3& hi) const {
    if (!static_.MayBeOccupied(lo, hi)) return false;
    return static_.coarse_map_is_exact() || static_.AnyOccupied(lo, hi);
  }

  static bool FiniteDirection(const SensorRay& ray) {
    return std::isfinite(ray.d_W.x + ray.d_W.y + ray.d_W.z);
  }

  // The box of a ray's segment (of the origin alone if the range is
  // negative), grown by kReachMargin. The origin and range are finite.
  static void SegmentBox(const SensorRay& ray, Vec3* lo, Vec3* hi) {
    const double r = ray.range > 0 ? ray.range : 0;
    const Vec3 end = ray.p_W + ray.d_W * r;
    const double m =
        kReachMargin * (r + std::abs(ray.p_W.x) + std::abs(ray.p_W.y) + std::abs(ray.p_W.z));
    *lo = {std::min(ray.p_W.x, end.x) - m, std::min(ray.p_W.y, end.y) - m,
           std::min(ray.p_W.z, end.z) - m};
    *hi = {std::max(ray.p_W.x, end.x) + m, std::max(ray.p_W.y, end.y) + m,
           std::max(ray.p_W.z, end.z) + m};
  }

  // Bounds of all the batch's ray segments.
  static void RayBounds(std::span<const SensorRay> rays, Vec3* lo, Vec3* hi) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    *lo = {kInf, kInf, kInf};
    *hi = {-kInf, -kInf, -kInf};
    auto grow = [&](const Vec3& p) {
      *lo = {std::min(lo->x, p.x), std::min(lo->y, p.y), std::min(lo->z, p.z)};
      *hi = {std::max(hi->x, p.x), std::max(hi->y, p.y), std::max(hi->z, p.z)};
    };
    for (const SensorRay& ray : rays) {
      grow(ray.p_W);
      grow(ray.p_W + ray.d_W * std::max(ray.range, 0.0));
    }
  }

  // Robot and dynamic shapes whose footprint meets `box`, but for the
  // robot's own (`instance`) and those in `skip`; ascending. With the
  // early-out, those whose footprint's square meets it: a superset, which
  // SenseRay narrows down exactly as it does the grid's answer.
  void Candidates(const Aabb2& box, int instance, std::span<const ObjectId> skip,
                  std::vector<uint32_t>* out) const {
    if (options_.early_out) return footprint_grid_.Others(box, instance, skip, out);
    grid_.QueryAabb(box, out);
    size_t kept = 0;
    for (uint32_t c : *out) {
      const PlacedShape& shape = moving_[c];
      if (instance >= 0 && shape.instance == instance) continue;
      if (std::find(skip.begin(), skip.end(), shape.id) != skip.end()) continue;
      (*out)[kept++] = c;
    }
    out->resize(kept);
  }

  // Casts every ray of a batch, with one static test and one grid query
  // for the whole batch (the reference the early-out must match).
  void CastAll(std::span<const SensorRef> sensors, int instance, std::span<const ObjectId> skip,
               Scene* scene) const {
    thread_local std::vector<SensorRay> rays;
    MakeRays(*scene, Table(*scene).rows, sensors, &rays);
    Vec3 lo, hi;
    RayBounds(rays, &lo, &hi);
    // Most batches of a swarm are nowhere near a wall.
    const bool near_static = static_.AnyOccupied(lo, hi);
    // Shapes of other robots (and dynamic shapes) whose footprint meets the batch.
    thread_local std::vector<uint32_t> candidates;
    Candidates({lo.x, lo.y, hi.x, hi.y}, instance, skip, &candidates);
    for (const SensorRay& ray : rays) SenseRay(ray, near_static, candidates, skip, scene);
  }

  // Casts one ray: against the static index if `near_static`, and against
  // the candidates whose footprint meets the ray's box. `candidates` may be
  // any superset (ascending) of those: the others are not tested.
  void SenseRay(const SensorRay& ray, bool near_static, std::span<const uint32_t> candidates,
                std::span<const ObjectId> skip, Scene* scene) const {
    double best = std::numeric_limits<double>::infinity();
    ObjectId hit;
    const PlacedShape* hit_shape = nullptr;
    if (ray.range >= 0) {
      double t;
      uint32_t s;
      if (near_static && static_.CastRay(ray.p_W, ray.d_W, ray.range, skip, &t, &s))
        best = t, hit = static_.shapes()[s].id, hit_shape = &static_.shapes()[s];
      const Vec3 end = ray.p_W + ray.d_W * ray.range;
      const Aabb2 box{std::min(ray.p_W.x, end.x), std::min(ray.p_W.y, end.y),
                      std::max(ray.p_W.x, end.x), std::max(ray.p_W.y, end.y)};
      for (uint32_t c : candidates) {
        if (!SpatialGrid::CircleIntersectsAabb(footprints_[c], box)) continue;
        if (RayCast(moving_[c], ray.p_W, ray.d_W, ray.range, &t) && t < best)
          best = t, hit = moving_[c].id, hit_shape = &moving_[c];
      }
    }
    Rows<ProximitySensorData>& table = Table(scene);
    ProximitySensorData& reading = table.rows[ray.row];
    reading.detected = best <= ray.range;
    // The surface normal at the hit, in the sensor frame, and the cut-off.
    if (reading.detected) {
      const Quat q_SW = scene->world_pose_at(table.owners[ray.row]).q.Conjugate();
      reading.normal = q_SW.Rotate(SurfaceNormal(*hit_shape, ray.p_W + ray.d_W * best));
      if (reading.settings->max_detection_angle < kPi && best > 0 &&
          -reading.normal.z < std::cos(reading.settings->max_detection_angle))
        reading.detected = false;
    }
    reading.distance = reading.detected ? best : 0;
    reading.detected_object = reading.detected ? hit : ObjectId{};
    if (reading.detected) Finish(table.owners[ray.row], &reading);
  }

  // A detection's noise (and failure), and its value on a response curve
  // (out of line: the plain ray's path stays as short as it was).
  void Finish(uint32_t slot, ProximitySensorData* reading) const {
    const ProximitySensorSettings& settings = *reading->settings;
    if (settings.noise.any() || settings.has_response()) [[unlikely]]
      FinishNoisyOrCurved(slot, reading);
  }
  [[gnu::noinline]] void FinishNoisyOrCurved(uint32_t slot, ProximitySensorData* reading) const {
    if (reading->settings->noise.any()) {
      AddNoise(slot, reading);
    } else {
      reading->value = static_cast<float>(ResponseValue(*reading));
    }
  }

  // A detection's value on its sensor's response curve: the curve at the
  // distance, its part above the far end times the cosine of the angle
  // between the line of sight and the surface normal (Lambertian).
  static double ResponseValue(const ProximitySensorData& reading) {
    const double d = reading.distance;
    const double cos_i = d > 0 ? -reading.normal.Dot(reading.p_SD()) / d : 1.0;
    return reading.settings->ResponseAt(d, cos_i);
  }

  // Noise and failure on a detection (sensor_noise.h), from the stream of
  // (seed, sensor slot, step): the same whatever thread reads the sensor.
  // Nothing is added to a sensor that detects nothing: noise moves a
  // detection or loses it, it never makes one.
  void AddNoise(uint32_t slot, ProximitySensorData* reading) const {
    const NoiseSettings& noise = reading->settings->noise;
    Rng rng = NoiseStream(seed_, slot, static_cast<int64_t>(step_), NoisePurpose::kProximity);
    if (Fails(noise, rng)) {
      reading->detected = false;
      reading->distance = 0;
      reading->detected_object = ObjectId{};
      reading->point = reading->normal = Vec3{};
      return;
    }
    // A response curve's value is what the noise perturbs, within the curve's values.
    if (reading->settings->has_response()) {
      double v = ResponseValue(*reading);
      if (noise.perturbs())
        v = std::clamp(Perturb(noise, v, rng), reading->settings->ResponseMin(),
                       reading->settings->ResponseMax());
      reading->value = static_cast<float>(v);
      return;
    }
    if (!noise.perturbs()) return;
    const double d = std::clamp(Perturb(noise, reading->distance, rng), 0.0, reading->range());
    if (reading->volume() != ProximityVolume::kRay && reading->distance > 0)
      reading->point = reading->point * (d / reading->distance);
    reading->distance = d;
  }

  // --- Volume sensors (volume.h) and randomized rays -------------------------

  // Calls visit(shape) for every shape (static first, then other robots' and
  // dynamic shapes in row order) whose world bounds meet [lo, hi] and that
  // the sensor may detect.
  template <class Visit>
  void VisitShapesNear(ObjectId sensor, const Vec3& lo, const Vec3& hi, int instance,
                       std::span<const ObjectId> skip, Visit&& visit) const {
    auto meets = [&](const Vec3& a, const Vec3& b) {
      return a.x <= hi.x && b.x >= lo.x && a.y <= hi.y && b.y >= lo.y && a.z <= hi.z && b.z >= lo.z;
    };
    auto detectable = [&](ObjectId shape) {
      if (std::find(skip.begin(), skip.end(), shape) != skip.end()) return false;
      return !detectable_ || detectable_(sensor, shape);
    };
    if (!static_.empty() && AnyOccupied(lo, hi)) {
      thread_local std::vector<uint32_t> near;
      static_.ShapesInBox(lo, hi, &near);
      const auto shapes = static_.shapes();
      for (uint32_t s : near)
        if (meets(static_lo_[s], static_hi_[s]) && detectable(shapes[s].id)) visit(shapes[s]);
    }
    thread_local std::vector<uint32_t> candidates;
    candidates.clear();
    Candidates({lo.x, lo.y, hi.x, hi.y}, instance, skip, &candidates);
    for (uint32_t c : candidates) {
      Vec3 a, b;
      WorldBounds(moving_[c], &a, &b);
      if (meets(a, b) && detectable(moving_[c].id)) visit(moving_[c]);
    }
  }

  // World box of a sensor-frame box (its 8 corners through X_WS), grown by a margin.
  static void WorldBox(const Pose& X_WS, const Vec3& lo_S, const Vec3& hi_S, Vec3* lo, Vec3* hi) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    *lo = {kInf, kInf, kInf};
    *hi = {-kInf, -kInf, -kInf};
    for (int i = 0; i < 8; ++i) {
      const Vec3 p =
          X_WS * Vec3{i & 1 ? hi_S.x : lo_S.x, i & 2 ? hi_S.y : lo_S.y, i & 4 ? hi_S.z : lo_S.z};
      *lo = {std::min(lo->x, p.x), std::min(lo->y, p.y), std::min(lo->z, p.z)};
      *hi = {std::max(hi->x, p.x), std::max(hi->y, p.y), std::max(hi->z, p.z)};
    }
    const double m = kReachMargin * (1 + (hi_S - lo_S).Norm() + X_WS.p.Norm());
    *lo = *lo - Vec3{m, m, m};
    *hi = *hi + Vec3{m, m, m};
  }

  // Reads a volume or randomized-ray sensor: the nearest point of the
  // detectable shapes' parts inside its volume.
  void SenseVolume(const SensorRef& sensor, int instance, std::span<const ObjectId> skip,
                   Scene* scene) const {
    ProximitySensorData& reading = Table(scene).rows[sensor.row];
    const Pose& X_WS = scene->world_pose_at(sensor.slot);
    const ObjectId sensor_id = scene->IdAt(sensor.slot);
    const Volume volume = MakeVolume(reading);
    Vec3 lo_S, hi_S, lo, hi;
    VolumeBounds(volume, &lo_S, &hi_S);
    WorldBox(X_WS, lo_S, hi_S, &lo, &hi);
    VolumeHit best{std::numeric_limits<double>::infinity(), {}, {}};
    ObjectId hit;
    const bool usable = std::isfinite(X_WS.p.x + X_WS.p.y + X_WS.p.z + reading.range());
    if (usable && volume.kind == ProximityVolume::kRandomizedRay) {
      SenseRandomRays(reading, sensor, X_WS, lo, hi, instance, skip, &best, &hit, scene);
    } else if (usable) {
      const Pose X_SW = X_WS.Inverse();
      VisitShapesNear(sensor_id, lo, hi, instance, skip, [&](const PlacedShape& shape) {
        VolumeHit h;
        if (NearestInVolume(volume, shape, X_SW, best.distance, &h)) best = h, hit = shape.id;
      });
    }
    reading.detected = best.distance <= reading.range();
    reading.distance = reading.detected ? best.distance : 0;
    reading.detected_object = reading.detected ? hit : ObjectId{};
    reading.point = reading.detected ? best.point : Vec3{};
    reading.normal = reading.detected ? best.normal : Vec3{};
    if (reading.detected) Finish(sensor.slot, &reading);
  }

  // `ray_count` rays in the cone, from the stream of (seed, sensor slot,
  // step): the same rays whatever thread reads the sensor.
  void SenseRandomRays(const ProximitySensorData& reading, const SensorRef& sensor,
                       const Pose& X_WS, const Vec3& lo, const Vec3& hi, int instance,
                       std::span<const ObjectId> skip, VolumeHit* best, ObjectId* hit,
                       const Scene* scene) const {
    thread_local std::vector<Vec3> directions;
    thread_local std::vector<const PlacedShape*> shapes;
    directions.resize(reading.settings->ray_count);
    const uint64_t stream = (uint64_t{sensor.slot} << 40) ^ step_;
    RandomRayDirections(seed_, stream, reading.settings->angle, reading.settings->ray_count,
                        directions.data());
    shapes.clear();
    VisitShapesNear(scene->IdAt(sensor.slot), lo, hi, instance, skip,
                    [&](const PlacedShape& shape) { shapes.push_back(&shape); });
    const double cos_cut = reading.settings->max_detection_angle < kPi
                               ? std::cos(reading.settings->max_detection_angle)
                               : -2;
    for (const Vec3& d_S : directions) {
      const Vec3 d_W = X_WS.q.Rotate(d_S);
      double nearest = std::min(best->distance, reading.range());
      const PlacedShape* nearest_shape = nullptr;
      for (const PlacedShape* shape : shapes) {
        double t;
        if (RayCast(*shape, X_WS.p, d_W, nearest, &t) && (t < nearest || !nearest_shape))
          nearest = t, nearest_shape = shape;
      }
      if (!nearest_shape || nearest >= best->distance) continue;
      const Vec3 normal =
          X_WS.q.Conjugate().Rotate(SurfaceNormal(*nearest_shape, X_WS.p + d_W * nearest));
      if (nearest > 0 && -normal.Dot(d_S) < cos_cut) continue;
      *best = {nearest, d_S * nearest, normal};
      *hit = nearest_shape->id;
    }
  }

  static constexpr double kPi = 3.141592653589793;

  // Shape rows a block of Update's placing: one task's work.
  static constexpr size_t kPlaceBlock = 4096;

  // place(b) for blocks b = 0 .. blocks - 1, on every thread if there is a
  // scheduler (each block writes only its own entries).
  template <class Place>
  void ForEachBlock(size_t blocks, Place&& place) const {
    if (scheduler_ == nullptr || blocks < 2) {
      for (size_t b = 0; b < blocks; ++b) place(b);
      return;
    }
    scheduler_->ParallelFor(0, static_cast<int64_t>(blocks), 1, [&](int64_t begin, int64_t end) {
      for (int64_t b = begin; b < end; ++b) place(static_cast<size_t>(b));
    });
  }

  BackendOptions options_;
  StaticIndex static_;
  std::vector<Vec3> static_lo_, static_hi_;  // world bounds of static_.shapes() (static shapes)
  double resolution_ = 0.05;                 // of the static index's octree, m
  StaticFollower follower_;                  // the static shapes that moved, and those indexed
  uint64_t seed_ = 1;                        // the world's seed
  TaskScheduler* scheduler_ = nullptr;       // populates the first sizing's pages
  uint64_t step_ = 0;                        // the step being sensed
  DetectableFilter detectable_;              // unset: every shape is detectable
  std::vector<PlacedShape> moving_;   // robot and dynamic shapes, by shape row order (moving)
  std::vector<GridItem> footprints_;  // their footprints, item i: moving_[i] (moving)
  std::vector<Aabb2> squares_;        // bounding squares, grown (moving)
  std::vector<int32_t> instances_;    // moving_[i].instance (moving)
  std::vector<ObjectId> ids_;         // moving_[i].id (moving)
  std::vector<FootprintMemo> footprint_memos_;  // by shape row (shapes)
  std::vector<uint32_t> block_start_;           // Update: first entry of each block of shape rows
  FootprintGrid footprint_grid_;                // with the early-out
  SpatialGrid grid_;                            // casting every ray
  // The sensors by owner, as of ListSensors() (see SensorListsCurrent).
  std::vector<uint32_t> instance_sensor_start_;  // first of each instance's sensors (instances + 1)
  std::vector<SensorRef> instance_sensors_;      // robot ray sensors, grouped by instance
  std::vector<uint32_t> instance_volume_start_;  // the same for volume sensors (instances + 1)
  std::vector<SensorRef> instance_volumes_;      // robot volume sensors, grouped by instance
  std::vector<SensorRef> scene_sensors_;         // sensors of no robot, by row
  ObjectType sensor_type_{};                     // the proximity_sensor type's value in the scene
  bool have_sensor_type_ = false;  // false: the scene has no such type (so no sensors)
  uint64_t listed_version_ = ~uint64_t{0};
  size_t listed_instances_ = 0;
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"proximity", "proximity", "1.0.0",
          "proximity sensors (rays, randomized rays, cone, pyramid, cylinder and disc volumes): "
          "exact distances to boxes, cylinders, spheres, capsules and triangle meshes; static "
          "environment in an OctoMap octree, robots through a spatial grid"};
}

std::unique_ptr<ProximityBackend> MakeBackend(const BackendOptions& options) {
  return std::make_unique<OctreeGridProximity>(options);
}

}  // namespace swarmsim::proximity
