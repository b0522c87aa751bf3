// Swarm metrics of clustering by LED colour (kind "metric", record phase,
// order 100, as modules/metrics): a world file's `metrics:` names them.
// A robot's colour is that of its first lit LED in hierarchy order; its
// position its model root's (x, y). Robots without a lit LED do not count.
//   same_color_neighbor_fraction  mean over robots of the share of their
//                                 kNeighbors nearest coloured robots that
//                                 have their colour (about 1/colours when
//                                 mixed, 1 when segregated)
//   color_dispersion              mean distance from each robot to the
//                                 centroid of the robots of its colour, m
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/spatial_grid.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/blobs/module.h"

namespace swarmsim::blobs {

namespace {

constexpr int kNeighbors = 3;

struct ColoredRobot {
  double x, y;
  std::array<double, 3> color;
};

// The live robots with a lit LED, in robot order.
void ColoredRobots(const World& world, std::vector<ColoredRobot>* out) {
  out->clear();
  const Scene& scene = world.scene();
  ObjectType led_type;
  if (!scene.FindType(kLedTypeName, &led_type)) return;
  const auto& leds = static_cast<const Rows<LedRow>&>(*scene.rows(led_type));
  if (leds.size() == 0) return;
  for (const ModelInstance& robot : scene.instances()) {
    if (!robot.alive) continue;
    for (uint32_t slot : robot.objects) {
      if (scene.type_at(slot) != led_type) continue;
      const LedRow& led = leds.rows[scene.row_at(slot)];
      if (!led.lit()) continue;
      const Vec3& p = scene.world_pose(robot.root).p;
      out->push_back({p.x, p.y, {led.color.x, led.color.y, led.color.z}});
      break;
    }
  }
}

class SameColorNeighborFraction : public Observer {
 public:
  explicit SameColorNeighborFraction(int every) : every_(every) {}
  // Snapshots: nothing kept between steps (the vectors are this step's).
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Record(const World& world, std::vector<MetricSample>* out) override {
    if (world.step_count() % every_ != 0) return;
    ColoredRobots(world, &robots_);
    const size_t n = robots_.size();
    if (n < 2) return;
    items_.clear();
    for (uint32_t i = 0; i < n; ++i) items_.push_back({robots_[i].x, robots_[i].y, 0, i});
    grid_.Build(items_);
    const size_t k = std::min<size_t>(kNeighbors, n - 1);
    double sum = 0;
    for (uint32_t i = 0; i < n; ++i) {
      // Widen the disc until it holds k others (only those inside it are sure).
      for (double r = std::max(grid_.cell_size(), 1e-3);; r *= 2) {
        grid_.QueryCircle(robots_[i].x, robots_[i].y, r, &hits_);
        near_.clear();
        for (uint32_t j : hits_) {
          const double d = std::hypot(robots_[j].x - robots_[i].x, robots_[j].y - robots_[i].y);
          if (j != i && d <= r) near_.emplace_back(d, j);
        }
        if (near_.size() >= k) break;
      }
      std::partial_sort(near_.begin(), near_.begin() + static_cast<ptrdiff_t>(k), near_.end());
      size_t same = 0;
      for (size_t m = 0; m < k; ++m) same += robots_[near_[m].second].color == robots_[i].color;
      sum += static_cast<double>(same) / static_cast<double>(k);
    }
    out->push_back({world.step_count(), world.time(), -1, "same_color_neighbor_fraction",
                    sum / static_cast<double>(n)});
  }

 private:
  int every_;
  std::vector<ColoredRobot> robots_;
  std::vector<GridItem> items_;
  SpatialGrid grid_;
  std::vector<uint32_t> hits_;
  std::vector<std::pair<double, uint32_t>> near_;  // (distance, robot)
};

class ColorDispersion : public Observer {
 public:
  explicit ColorDispersion(int every) : every_(every) {}
  // Snapshots: nothing kept between steps.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Record(const World& world, std::vector<MetricSample>* out) override {
    if (world.step_count() % every_ != 0) return;
    ColoredRobots(world, &robots_);
    if (robots_.empty()) return;
    struct Sum {
      double x = 0, y = 0;
      int count = 0;
    };
    std::map<std::array<double, 3>, Sum> groups;
    for (const ColoredRobot& r : robots_) {
      Sum& g = groups[r.color];
      g.x += r.x, g.y += r.y, ++g.count;
    }
    double sum = 0;
    for (const ColoredRobot& r : robots_) {
      const Sum& g = groups[r.color];
      sum += std::hypot(r.x - g.x / g.count, r.y - g.y / g.count);
    }
    out->push_back({world.step_count(), world.time(), -1, "color_dispersion",
                    sum / static_cast<double>(robots_.size())});
  }

 private:
  int every_;
  std::vector<ColoredRobot> robots_;
};

// The descriptor of a metric `M`, made with its `every` (a const int*;
// null: every step).
template <class M>
ModuleDescriptor MetricModule(const char* name, const char* description) {
  return {{"metric", name, "1.0", description},
          PhaseBit(Phase::kRecord),
          100,
          false,
          [](World*, const void* config) -> std::unique_ptr<Module> {
            const int every = config != nullptr ? *static_cast<const int*>(config) : 1;
            if (every < 1) throw Error("a metric's 'every' must be >= 1");
            return std::make_unique<M>(every);
          }};
}

}  // namespace

void RegisterColorMetrics(ModuleRegistry* registry) {
  registry->RegisterModule(MetricModule<SameColorNeighborFraction>(
      "same_color_neighbor_fraction",
      "mean share of each robot's 3 nearest LED-carrying robots that have its LED colour"));
  registry->RegisterModule(MetricModule<ColorDispersion>(
      "color_dispersion",
      "mean distance from each robot to the centroid of the robots of its LED colour (m)"));
}

}  // namespace swarmsim::blobs
