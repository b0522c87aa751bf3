// The blob cameras' module (internal to modules/blobs): in the sense phase
// it indexes the lit LEDs and the shapes that may hide them, then fills
// every blob camera's reading, cameras in parallel.
#pragma once

#include <cstdint>
#include <vector>

#include "framework/device_access.h"
#include "framework/module.h"
#include "framework/object_rows.h"
#include "framework/spatial_grid.h"
#include "modules/proximity/ray_cast.h"

namespace swarmsim {
class ModuleRegistry;
class LineOfSight;
struct BlobCameraRow;
}  // namespace swarmsim

namespace swarmsim::blobs {

inline constexpr const char* kModuleName = "blobs";

// The metrics of colour clustering (metrics.cc).
void RegisterColorMetrics(ModuleRegistry* registry);

// Also the plugins' set_led (framework/device_access.h).
class BlobCameraModule final : public Module, public LedAccess {
 public:
  // Snapshots (framework/world_state.h): nothing to save here: the LEDs' and cameras' rows
  // (objects.cc) hold every state a step carries to the next; the indexes above are rebuilt each
  // sense phase.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Sense(World* world) override;
  int SetLed(Scene* scene, int robot, ObjectId id, const Vec3& color,
             bool on) const noexcept override;

 private:
  struct LitLed {  // 64 bytes
    Vec3 p_W;      // its centre
    Vec3 color;
    ObjectId id;
    int32_t instance;  // its robot, or -1
    uint32_t slot;
  };
  // A shape that may hide an LED.
  struct Occluder {
    proximity::PlacedShape shape;
    Vec3 lo, hi;  // its world bounds, grown for rounding
    uint32_t slot;
  };

  void IndexLeds(const Scene& scene, ObjectType led_type);
  // The shapes whose heights meet [z_lo, z_hi] (no segment from a camera
  // to an LED leaves that band).
  void IndexOccluders(const Scene& scene, double z_lo, double z_hi);
  // Fills one camera's reading. Thread-safe across cameras.
  void See(const Scene& scene, uint32_t slot, BlobCameraRow* camera) const;
  // Adds the camera's noise to its blobs, from a stream keyed by (the
  // world's seed, the camera's slot, the step).
  void AddNoise(uint32_t slot, BlobCameraRow* camera) const;
  // The occluders whose (x, y) bounds meet the camera's range disc and
  // whose heights meet [z_lo, z_hi], but those of the camera's robot (or,
  // for a camera of no robot, those it hangs from).
  void ListOccluders(const Scene& scene, const Vec3& p_W, double range, int instance, uint32_t slot,
                     double z_lo, double z_hi, std::vector<uint32_t>* out) const;
  // Does one of `occluders` (but the LED's robot's, or the shapes it hangs
  // from) or the map cross the segment from the camera at p_W to `led`?
  bool Hidden(const Scene& scene, const Vec3& p_W, const LitLed& led, double distance,
              const std::vector<uint32_t>& occluders) const;

  uint64_t seed_ = 0;  // the world's
  uint64_t step_ = 0;  // the step being sensed
  bool types_found_ = false;
  bool have_types_ = false;
  ObjectType led_type_{}, camera_type_{};
  // The environment map's voxels: the world's line of sight
  // (framework/line_of_sight.h, the proximity module's); null when the
  // scene has no map.
  const LineOfSight* map_ = nullptr;
  std::vector<LitLed> leds_;         // lit LEDs (LED rows order)
  std::vector<GridItem> led_items_;  // their xy (leds_)
  SpatialGrid led_grid_;
  std::vector<Occluder> occluders_;       // (occluders)
  std::vector<GridItem> occluder_items_;  // their xy footprint circles (occluders)
  SpatialGrid occluder_grid_;
};

}  // namespace swarmsim::blobs
