// The proximity backend's interface (modules/proximity): ray and volume
// sensors against the static environment and against other robots. The
// module (module.cc) drives one per world; benchmarks and tests drive
// one directly (proximity.h's MakeBackend).
#pragma once

#include <cstdint>
#include <functional>

#include "framework/handle.h"
#include "framework/line_of_sight.h"
#include "framework/math.h"

namespace swarmsim {

class Scene;
class TaskScheduler;

struct ProximitySettings {
  double octree_resolution = 0.05;  // m, voxel size of the static environment's octree
  uint64_t seed = 1;                // the world's seed: randomized-ray sensors draw from it
  // The world's threads: the first Update populates its buffers' pages on
  // them (framework/prefault.h). Null: on the caller, as it writes them.
  TaskScheduler* scheduler = nullptr;
};

// May the sensor `sensor` detect the shape `shape`? The hook for per-sensor
// detectable sets (collections): unset, every sensor detects every shape
// (but its own robot's). Called concurrently from the sense phase; applied
// to volume and randomized-ray sensors. `shape` is null for a voxel of the
// Scene's environment map.
using DetectableFilter = std::function<bool(ObjectId sensor, ObjectId shape)>;

// Also the world's line-of-sight service (framework/line_of_sight.h): its
// static index answers.
class ProximityBackend : public LineOfSight {
 public:
  // Indexes the static environment (shapes that belong to no robot and are
  // not dynamic, and the Scene's environment map, whose boxes a reading
  // reports as a null object). Called once at start.
  virtual void Build(const Scene& scene, const ProximitySettings& settings) = 0;
  // Follows the static shapes: one that a script, a path or a joint moved
  // is sensed where it is from then on (placed with the moving shapes), and
  // one added or removed is indexed again. Called once per step before
  // Update(), also when no sensor exists (the line of sight reads them).
  virtual void FollowStaticShapes(const Scene& scene) { (void)scene; }
  // Rebuilds per-step acceleration structures (the spatial grid of robots)
  // from the current poses. Called once per step before Sense().
  virtual void Update(const Scene& scene) = 0;
  // Fills the readings of every proximity sensor of model instance
  // `instance`. Called concurrently for different instances: it must only
  // write those sensors' readings.
  virtual void SenseInstance(Scene* scene, int instance) const = 0;
  // Fills the readings of sensors that belong to no robot.
  virtual void SenseSceneSensors(Scene* scene) const = 0;
  // The step about to be sensed (randomized rays are keyed by it).
  virtual void SetStep(uint64_t step) { (void)step; }
  // Sets (or, empty, clears) the detectable-set filter.
  virtual void SetDetectableFilter(DetectableFilter filter) { (void)filter; }
  // Does a static shape (where it is now) cross the segment a-b (world
  // frame, m)? Used for line-of-sight messages. Thread-safe. Default: nothing blocks.
  bool SegmentBlocked(const Vec3& a_W, const Vec3& b_W) const override {
    (void)a_W;
    (void)b_W;
    return false;
  }
};

}  // namespace swarmsim
