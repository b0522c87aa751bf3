// The proximity backend: ray sensors against the static environment (an
// OctoMap octree built once, see static_index.h) and against robots and
// dynamic shapes (a spatial grid rebuilt every step).
//
// Detection rules:
// - A sensor is a ray from its origin along its +z axis, of length `range`.
// - The nearest exact hit wins; on an exact tie the static environment wins,
//   then the lower shape row (deterministic).
// - A ray that starts inside or on a shape hits it at distance 0.
// - A robot's sensors never see that robot's own shapes; a sensor that
//   belongs to no robot never sees the shapes it is mounted on (its ancestors).
// - Static shapes (no robot, not dynamic) are frozen at Build(): moving one
//   later, or adding one, is not seen. Make such a shape dynamic or part of
//   a model if it moves.
#include "modules/proximity/proximity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "framework/scene.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/ray_cast.h"
#include "modules/proximity/static_index.h"

namespace swarmsim::proximity {
namespace {

struct SensorRay {  // 64 bytes
  Vec3 p_W;         // ray origin in the world
  Vec3 d_W;         // unit direction in the world
  double range;     // m
  uint32_t row;     // row in Scene::proximity_sensors()
};

SensorRay MakeRay(const Scene& scene, uint32_t slot) {
  const Pose& X_WS = scene.world_pose_at(slot);
  const uint32_t row = scene.row_at(slot);
  Vec3 d = X_WS.q.Rotate({0, 0, 1});
  // Unit already unless the pose's quaternion drifted; skip the sqrt then.
  const double norm2 = d.SquaredNorm();
  if (std::abs(norm2 - 1) > 1e-14 && norm2 > 0) d = d / std::sqrt(norm2);
  return {X_WS.p, d, scene.proximity_sensors()[row].range, row};
}

class OctreeGridProximity final : public ProximityBackend {
 public:
  void Build(const Scene& scene, const ProximitySettings& settings) override {
    static_.Build(scene, settings.octree_resolution);
    Update(scene);
  }

  // Places every robot shape and dynamic shape and rebuilds the grid over
  // their footprints. Buffers keep their capacity: no allocation once warm.
  void Update(const Scene& scene) override {
    moving_.clear();
    items_.clear();
    const auto shapes = scene.shapes();
    const auto owners = scene.shape_owners();
    for (size_t r = 0; r < shapes.size(); ++r) {
      const uint32_t slot = owners[r];
      const int instance = scene.instance_of_at(slot);
      if (instance < 0 && !shapes[r].dynamic) continue;
      const Pose& X_WS = scene.world_pose_at(slot);
      items_.push_back({X_WS.p.x, X_WS.p.y, WorldFootprintRadius(shapes[r], X_WS),
                        static_cast<uint32_t>(moving_.size())});
      moving_.push_back(PlaceShape(shapes[r], X_WS, scene.IdAt(slot), instance));
    }
    grid_.Build(items_);
  }

  void SenseInstance(Scene* scene, int instance) const override {
    thread_local std::vector<SensorRay> rays;
    rays.clear();
    for (uint32_t slot : scene->instance(instance).objects)
      if (scene->type_at(slot) == ObjectType::kProximitySensor)
        rays.push_back(MakeRay(*scene, slot));
    SenseRays(rays, instance, {}, scene);
  }

  bool SegmentBlocked(const Vec3& a_W, const Vec3& b_W) const override {
    const Vec3 d = b_W - a_W;
    const double length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (!(length > 0) || static_.empty()) return false;
    double t = 0;
    uint32_t shape = 0;
    return static_.CastRay(a_W, d * (1 / length), length, {}, &t, &shape);
  }

  void SenseSceneSensors(Scene* scene) const override {
    thread_local std::vector<ObjectId> mounts;
    const auto owners = scene->proximity_sensor_owners();
    for (size_t row = 0; row < owners.size(); ++row) {
      const uint32_t slot = owners[row];
      if (scene->instance_of_at(slot) >= 0) continue;
      // The shapes the sensor hangs from are not obstacles to it.
      mounts.clear();
      for (int32_t a = scene->parent_at(slot); a >= 0; a = scene->parent_at(a))
        if (scene->type_at(a) == ObjectType::kShape) mounts.push_back(scene->IdAt(a));
      const SensorRay ray = MakeRay(*scene, slot);
      SenseRays({&ray, 1}, -1, mounts, scene);
    }
  }

 private:
  // Reads a batch of rays of one robot (`instance`, or -1 for scene sensors)
  // with one static early-out and one grid query for the whole batch.
  void SenseRays(std::span<const SensorRay> rays, int instance, std::span<const ObjectId> skip,
                 Scene* scene) const {
    if (rays.empty()) return;
    // Bounds of all the batch's ray segments.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    auto grow = [&](const Vec3& p) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    };
    for (const SensorRay& ray : rays) {
      grow(ray.p_W);
      grow(ray.p_W + ray.d_W * std::max(ray.range, 0.0));
    }
    // Most batches of a swarm are nowhere near a wall.
    const bool near_static = static_.AnyOccupied(lo, hi);
    // Shapes of other robots (and dynamic shapes) whose footprint meets the batch.
    thread_local std::vector<uint32_t> candidates;
    grid_.QueryAabb({lo.x, lo.y, hi.x, hi.y}, &candidates);
    size_t kept = 0;
    for (uint32_t c : candidates) {
      const PlacedShape& shape = moving_[c];
      if (instance >= 0 && shape.instance == instance) continue;
      if (std::find(skip.begin(), skip.end(), shape.id) != skip.end()) continue;
      candidates[kept++] = c;
    }
    candidates.resize(kept);

    for (const SensorRay& ray : rays) {
      double best = kInf;
      ObjectId hit;
      if (ray.range >= 0) {
        double t;
        uint32_t s;
        if (near_static && static_.CastRay(ray.p_W, ray.d_W, ray.range, skip, &t, &s))
          best = t, hit = static_.shapes()[s].id;
        const Vec3 end = ray.p_W + ray.d_W * ray.range;
        const Aabb2 box{std::min(ray.p_W.x, end.x), std::min(ray.p_W.y, end.y),
                        std::max(ray.p_W.x, end.x), std::max(ray.p_W.y, end.y)};
        for (uint32_t c : candidates) {
          if (!SpatialGrid::CircleIntersectsAabb(items_[c], box)) continue;
          if (RayCast(moving_[c], ray.p_W, ray.d_W, ray.range, &t) && t < best)
            best = t, hit = moving_[c].id;
        }
      }
      ProximitySensorData& reading = scene->proximity_sensors()[ray.row];
      reading.detected = best <= ray.range;
      reading.distance = reading.detected ? best : 0;
      reading.p_SD = {0, 0, reading.distance};
      reading.detected_object = reading.detected ? hit : ObjectId{};
    }
  }

  StaticIndex static_;
  std::vector<PlacedShape> moving_;  // robot and dynamic shapes, by shape row order (moving)
  std::vector<GridItem> items_;      // their footprints; item i is moving_[i] (moving)
  SpatialGrid grid_;
};

}  // namespace

swarmsim::ModuleInfo ModuleInfo() {
  return {"proximity", "proximity", "1.0.0",
          "ray proximity sensors: exact distances to boxes, cylinders, spheres and triangle "
          "meshes; static environment in an OctoMap octree, robots through a spatial grid"};
}

std::unique_ptr<ProximityBackend> MakeBackend() { return std::make_unique<OctreeGridProximity>(); }

}  // namespace swarmsim::proximity
