// The ground_sensor module: every world senses its ground sensors in the
// sense phase (order 120, after proximity), rows in parallel.
#include "framework/module.h"

#include <algorithm>
#include <memory>

#include "framework/device_access.h"
#include "framework/floor_layer.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/ground_sensor/ground_sensor.h"

namespace swarmsim::ground_sensor {

void RegisterModule(ModuleRegistry* registry);

namespace {

constexpr int64_t kRowGrain = 512;

// Also the plugins' read_sensor_value for ground sensors (framework/device_access.h).
class Sensing final : public Module, public SensorValueAccess {
 public:
  int ReadValue(const Scene& scene, ObjectId id, double* value) const noexcept override {
    // The type the sense phase found, once it looked (no search by name).
    ObjectType type = type_;
    if (!(type_found_ ? have_type_ : FindSensorType(scene, &type)) || !scene.IsValid(id)) return -1;
    const uint32_t slot = scene.SlotOf(id);
    if (scene.type_at(slot) != type) return -1;
    *value = scene.rows<GroundSensorRow>(type).rows[scene.row_at(slot)].value;
    return 0;
  }

  // Snapshots: the readings are the rows'; the seed is read at each sense.
  bool SaveState(const World&, StateWriter*) const override { return true; }

  void Sense(World* world) override {
    Scene& scene = world->scene();
    if (!type_found_) {
      have_type_ = FindSensorType(scene, &type_);
      type_found_ = true;
    }
    if (!have_type_) return;
    Rows<GroundSensorRow>& rows = scene.rows<GroundSensorRow>(type_);
    if (rows.size() == 0) return;
    const FloorLayer* floor = world->floor_layer();
    const uint64_t seed = world->settings().seed;
    const int64_t step = world->step_count();
    world->scheduler().ParallelFor(
        0, static_cast<int64_t>(rows.size()), kRowGrain, [&](int64_t begin, int64_t end) {
          SenseRows(scene, floor, seed, step, &rows, static_cast<size_t>(begin),
                    static_cast<size_t>(end));
        });
  }

 private:
  bool type_found_ = false;  // looked for the type (first sense phase)
  bool have_type_ = false;
  ObjectType type_{};
};

}  // namespace

void SenseRows(const Scene& scene, const FloorLayer* floor, uint64_t seed, int64_t step,
               Rows<GroundSensorRow>* rows, size_t begin, size_t end) {
  FloorArea area;
  const uint8_t* rgb = nullptr;
  if (floor != nullptr) {
    area = floor->floor_area();
    rgb = floor->floor_rgb().data();
  }
  for (size_t r = begin; r < end; ++r) {
    GroundSensorRow& row = rows->rows[r];
    const GroundSensorSettings& s = *row.settings;
    const uint32_t slot = rows->owners[r];
    // The floor's colour under the sensor's origin: its pixel, the background
    // outside its area, black without a floor.
    Vec3 color;
    if (rgb != nullptr) {
      const Vec3& p = scene.world_pose_at(slot).p;
      const int64_t pixel = FloorPixelAt(area, p.x, p.y);
      if (pixel < 0) {
        color = area.background;
      } else {
        const uint8_t* px = rgb + 3 * pixel;
        color = {px[0] / 255.0, px[1] / 255.0, px[2] / 255.0};
      }
    }
    // Noise and failure: drawn only for a sensor with noise keys.
    if (s.noise.any()) {
      Rng rng = NoiseStream(seed, slot, step, NoisePurpose::kGround);
      if (Fails(s.noise, rng)) {
        row.color = {};
        row.value = 0;
        continue;
      }
      if (s.noise.perturbs()) {
        if (s.mode == Mode::kColor) {
          color = {std::clamp(Perturb(s.noise, color.x, rng), 0.0, 1.0),
                   std::clamp(Perturb(s.noise, color.y, rng), 0.0, 1.0),
                   std::clamp(Perturb(s.noise, color.z, rng), 0.0, 1.0)};
        } else {
          const double grey = Perturb(s.noise, Grey(color), rng);
          row.value = s.mode == Mode::kBinary ? (grey >= s.threshold ? 1.0 : 0.0)
                                              : std::clamp(grey, 0.0, 1.0);
          row.color = {row.value, row.value, row.value};
          continue;
        }
      }
    }
    switch (s.mode) {
      case Mode::kColor:
        row.color = color;
        row.value = Grey(color);
        break;
      case Mode::kGrey:
        row.value = Grey(color);
        row.color = {row.value, row.value, row.value};
        break;
      case Mode::kBinary:
        row.value = Grey(color) >= s.threshold ? 1.0 : 0.0;
        row.color = {row.value, row.value, row.value};
        break;
    }
  }
}

void RegisterModule(ModuleRegistry* registry) {
  registry->RegisterModule({{"sensor", "ground_sensor", "1.0",
                             "the floor under each ground sensor: colour, grey level or binary"},
                            PhaseBit(Phase::kSense),
                            120,
                            /*every_world=*/true,
                            [](World*, const void*) { return std::make_unique<Sensing>(); },
                            nullptr});
}

}  // namespace swarmsim::ground_sensor
