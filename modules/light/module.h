// The light sensing module (internal to modules/light): in the sense phase
// it lists the lit light sources (and, if a sensor asks, the shapes that
// may hide them), then fills every light sensor's reading, sensors in
// parallel.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "framework/device_access.h"
#include "framework/module.h"
#include "framework/object_rows.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/ray_cast.h"

struct lua_State;

namespace swarmsim {
class LineOfSight;
}

namespace swarmsim::light {

struct LightSensorRow;

inline constexpr const char* kModuleName = "light";

// The Lua area of both types (lua_api_light.cc).
void RegisterLightApi(lua_State* L);

// Also the plugins' read_sensor_value for light sensors (framework/device_access.h).
class LightSensingModule final : public Module, public SensorValueAccess {
 public:
  // Snapshots (framework/world_state.h): nothing to save here: the sources' and sensors' rows
  // (objects.cc) hold every state a step carries to the next; the indexes above are rebuilt each
  // sense phase.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Sense(World* world) override;
  int ReadValue(const Scene& scene, ObjectId id, double* value) const noexcept override;

 private:
  struct LitSource {   // 48 bytes
    Vec3 p_W;          // its centre
    double intensity;  // > 0
    int32_t instance;  // its robot, or -1
    uint32_t slot;
  };
  // A shape that may hide a light.
  struct Occluder {
    proximity::PlacedShape shape;
    Vec3 lo, hi;  // its world bounds, grown for rounding
    uint32_t slot;
  };
  // Shapes of one kind (static ones, or moving ones: a robot's or dynamic),
  // with a 2D grid over their (x, y) bounds when there are many.
  struct OccluderSet {
    std::vector<Occluder> occluders;
    std::vector<GridItem> items;  // their xy footprint circles (occluders)
    SpatialGrid grid;
    bool use_grid = false;                     // else every segment scans them all
    double z_lo = INFINITY, z_hi = -INFINITY;  // the heights their bounds span
    void Clear() {
      occluders.clear();
      items.clear();
      use_grid = false;
      z_lo = INFINITY, z_hi = -INFINITY;
    }
  };

  void IndexSources(const Scene& scene);
  // The shapes of the scene, static ones into static_ (if `static_shapes`)
  // and moving ones into moving_ (if `moving_shapes`).
  void IndexOccluders(const Scene& scene, bool static_shapes, bool moving_shapes);
  // robot_clear_: for each robot with light sensors and each lit light,
  // whether every segment from one of its sensors to the light surely
  // misses every static shape (the segment from its root to the light
  // misses their boxes grown by the farthest sensor's distance from the
  // root): its sensors then skip the static shapes for that light.
  void ClearRobots(World* world, const Rows<LightSensorRow>& sensors);
  // Fills one sensor's reading. Thread-safe across sensors.
  void Read(const Scene& scene, uint32_t slot, LightSensorRow* sensor) const;
  // Does a shape of `set` (but those of the sensor's robot and the light's,
  // or those either hangs from) cross the segment from p_W to q_W?
  bool Hidden(const Scene& scene, const OccluderSet& set, const Vec3& p_W, const Vec3& q_W,
              int sensor_instance, uint32_t sensor_slot, const LitSource& source) const;

  uint64_t seed_ = 0;  // the world's
  int64_t step_ = 0;   // the step being sensed
  bool types_found_ = false;
  bool have_types_ = false;
  ObjectType source_type_{}, sensor_type_{};
  // The world's line of sight (framework/line_of_sight.h), asked only for
  // the environment map's voxels: null when the scene has no map.
  const LineOfSight* map_ = nullptr;
  std::vector<LitSource> sources_;    // lit light sources (row order)
  OccluderSet static_, moving_;       // shapes (shape row order)
  std::vector<double> reach_;         // per robot: its sensors' farthest distance from its root
  std::vector<Vec3> roots_;           // per robot: its root's position (where reach_ >= 0)
  std::vector<uint8_t> robot_clear_;  // robots x sources_ (ClearRobots); empty: none known
};

}  // namespace swarmsim::light
