#include "modules/metrics/swarm_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "framework/error.h"
#include "framework/spatial_grid.h"
#include "framework/world.h"
#include "framework/world_state.h"

namespace swarmsim {

namespace {

// Positions of the live robots' roots, in robot order.
void RobotPositions(const World& world, std::vector<GridItem>* out) {
  out->clear();
  const Scene& scene = world.scene();
  for (const ModelInstance& inst : scene.instances()) {
    if (!inst.alive) continue;
    const Vec3& p = scene.world_pose(inst.root).p;
    out->push_back({p.x, p.y, 0, static_cast<uint32_t>(out->size())});
  }
}

// Mean over robots of the distance to the nearest other robot (centre to
// centre, in the plane), m. Grid queries keep it O(N) at constant density.
class MeanNearestNeighborDistance : public Observer {
 public:
  explicit MeanNearestNeighborDistance(int every) : every_(every) {}
  bool SaveState(const World&, StateWriter*) const override {
    return true;
  }  // nothing kept between steps
  void Record(const World& world, std::vector<MetricSample>* out) override {
    if (world.step_count() % every_ != 0) return;
    RobotPositions(world, &items_);
    if (items_.size() < 2) return;
    grid_.Build(items_);
    double sum = 0;
    std::vector<uint32_t> hits;
    for (uint32_t i = 0; i < items_.size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (double r = std::max(grid_.cell_size(), 1e-3); !std::isfinite(best); r *= 2) {
        grid_.QueryCircle(items_[i].x, items_[i].y, r, &hits);
        for (uint32_t j : hits) {
          if (j == i) continue;
          const double d = std::hypot(items_[j].x - items_[i].x, items_[j].y - items_[i].y);
          if (d <= r) best = std::min(best, d);  // only trust neighbours inside the searched disc
        }
      }
      sum += best;
    }
    out->push_back({world.step_count(), world.time(), -1, "mean_nearest_neighbor_distance",
                    sum / static_cast<double>(items_.size())});
  }

 private:
  int every_;
  std::vector<GridItem> items_;
  SpatialGrid grid_;
};

// Area visited by at least one robot since the start, m^2, on a grid of
// 0.25 m cells (about a foot-bot's diameter).
class CoveredArea : public Observer {
 public:
  explicit CoveredArea(int every) : every_(every) {}
  // Snapshots: the cells visited so far, in ascending order.
  bool SaveState(const World&, StateWriter* out) const override {
    std::vector<uint64_t> cells(visited_.begin(), visited_.end());
    std::sort(cells.begin(), cells.end());
    out->Put<uint64_t>(cells.size());
    out->PutBytes(cells.data(), cells.size() * sizeof(uint64_t));
    return true;
  }
  void LoadState(StateReader* in, World*) override {
    std::vector<uint64_t> cells(in->GetCount(sizeof(uint64_t)));
    in->GetBytes(cells.data(), cells.size() * sizeof(uint64_t));
    visited_ = std::unordered_set<uint64_t>(cells.begin(), cells.end());
  }
  // The cells the robots start in count too (they were left out: the area
  // was that of the cells entered from step 1 on).
  void Start(World* world) override { Visit(world->scene()); }
  void Record(const World& world, std::vector<MetricSample>* out) override {
    Visit(world.scene());
    if (world.step_count() % every_ != 0) return;
    out->push_back({world.step_count(), world.time(), -1, "covered_area",
                    static_cast<double>(visited_.size()) * kCell * kCell});
  }

 private:
  // The cells (a grid aligned with the world's axes, a corner at the
  // origin) the robots' roots are in now.
  void Visit(const Scene& scene) {
    for (const ModelInstance& inst : scene.instances()) {
      if (!inst.alive) continue;
      const Vec3& p = scene.world_pose(inst.root).p;
      const auto cx = static_cast<int64_t>(std::floor(p.x / kCell));
      const auto cy = static_cast<int64_t>(std::floor(p.y / kCell));
      visited_.insert((static_cast<uint64_t>(cx) << 32) ^ static_cast<uint32_t>(cy));
    }
  }
  static constexpr double kCell = 0.25;
  int every_;
  std::unordered_set<uint64_t> visited_;
};

}  // namespace

namespace metrics {

std::vector<ModuleDescriptor> SwarmMetricModules() {
  const auto every = [](const void* config) {
    const int n = config != nullptr ? *static_cast<const int*>(config) : 1;
    if (n < 1) throw Error("a metric's 'every' must be >= 1");
    return n;
  };
  return {
      {{"metric", "mean_nearest_neighbor_distance", "1.0",
        "mean distance from each robot to its nearest neighbour (m)"},
       PhaseBit(Phase::kRecord),
       100,
       false,
       [every](World*, const void* config) -> std::unique_ptr<Module> {
         return std::make_unique<MeanNearestNeighborDistance>(every(config));
       }},
      {{"metric", "covered_area", "1.0",
        "area visited by at least one robot since the start (m^2, 0.25 m cells)"},
       PhaseBit(Phase::kRecord),
       100,
       false,
       [every](World*, const void* config) -> std::unique_ptr<Module> {
         return std::make_unique<CoveredArea>(every(config));
       }},
  };
}

}  // namespace metrics
}  // namespace swarmsim
