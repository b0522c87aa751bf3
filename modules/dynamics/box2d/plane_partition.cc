// PartitionedPlaneWorld: regions, migration, ghosts and the concurrent
// substep (see "Partitions" in box2d_backend.h).
#include "modules/dynamics/box2d/plane_partition.h"

#include <box2d/b2_body.h>
#include <box2d/b2_common.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"

namespace swarmsim::box2d {

namespace {

// Ground fixtures farther than this from a region (m, plus four of the
// largest body's radius) are left out of it: no body it owns can reach them
// within a step.
constexpr double kGroundPad = 1.0;
// Ghost reach: a body's travel in a step is taken as this times its speed
// bound (its speed or its wheels' command) times the step's duration.
constexpr double kTravelFactor = 1.5;

double AlongAxis(const b2Vec2& p, int axis) { return axis == 0 ? p.x : p.y; }

}  // namespace

PartitionedPlaneWorld::PartitionedPlaneWorld(const Options& options,
                                             const DynamicsSettings& settings)
    : options_(options), settings_(settings) {
  // Checks the options (throws on bad ones) before anything is built.
  regions_.push_back(std::make_unique<PlaneWorld>(options_, settings_));
}

PartitionedPlaneWorld::~PartitionedPlaneWorld() = default;

int PartitionedPlaneWorld::ColumnOf(double along) const {
  return static_cast<int>(std::upper_bound(borders_.begin(), borders_.end(), along) -
                          borders_.begin());
}

int PartitionedPlaneWorld::RowOf(int column, double across) const {
  if (rows_ == 1) return 0;
  const std::vector<double>& borders = row_borders_[static_cast<size_t>(column)];
  return static_cast<int>(std::upper_bound(borders.begin(), borders.end(), across) -
                          borders.begin());
}

int PartitionedPlaneWorld::RegionOf(const b2Vec2& p) const {
  const int column = ColumnOf(AlongAxis(p, axis_));
  return column * rows_ + RowOf(column, AlongAxis(p, 1 - axis_));
}

template <class Fn>
void PartitionedPlaneWorld::ForEachRegion(Fn&& fn) {
  const int64_t count = static_cast<int64_t>(regions_.size());
  auto run = [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) fn(static_cast<size_t>(r));
  };
  if (settings_.scheduler && count > 1)
    settings_.scheduler->ParallelFor(0, count, 1, run);
  else
    run(0, count);
}

namespace {

// Borders cutting sorted positions into `parts` groups of the same size,
// each halfway between the last of one group and the first of the next.
// (Fewer positions than parts: the extra groups are empty, past the end.)
std::vector<double> QuantileBorders(const std::vector<double>& sorted, int64_t parts) {
  std::vector<double> borders;
  const int64_t n = static_cast<int64_t>(sorted.size());
  for (int64_t k = 1; k < parts; ++k) {
    const int64_t i = k * n / parts;
    if (n == 0)
      borders.push_back(0);
    else if (i == 0)
      borders.push_back(sorted.front() - 1);
    else if (i >= n)
      borders.push_back(sorted.back() + 1);
    else
      borders.push_back(0.5 *
                        (sorted[static_cast<size_t>(i - 1)] + sorted[static_cast<size_t>(i)]));
  }
  return borders;
}

}  // namespace

void PartitionedPlaneWorld::Build(const Scene& scene) {
  auto staging = std::make_unique<PlaneWorld>(options_, settings_);
  staging->Build(scene);
  obstacle_poses_ = staging->obstacle_poses();
  dynamic_range_ = staging->dynamic_range();
  regions_.clear();
  ground_reach_.clear();
  borders_.clear();
  row_borders_.clear();
  rows_ = 1;
  current_ = 0;
  const std::vector<PlaneBody>& bodies = staging->bodies();
  state_of_slot_.assign(scene.slot_count(), 0);
  for (uint32_t b = 0; b < bodies.size(); ++b) state_of_slot_[bodies[b].slot] = b;
  states_[0].assign(bodies.size(), {});
  states_[1].assign(bodies.size(), {});
  const int64_t body_total = static_cast<int64_t>(bodies.size());
  int64_t count = settings_.partitions;
  if (count <= 0)
    count = std::clamp<int64_t>(body_total / kAutoBodiesPerRegion, 1, kAutoMaxRegions);
  count = std::min(count, body_total);
  if (count <= 1 || !staging->CanPartition()) {
    regions_.push_back(std::move(staging));
    const double infinity = std::numeric_limits<double>::infinity();
    ground_reach_.push_back({-infinity, infinity, -infinity, infinity});
    return;
  }
  // Columns across the longer side of the bodies' bounding box, each holding
  // the same number of body centres at Build (borders halfway between two
  // neighbouring centres); up to kMaxStrips regions they are the regions
  // (strips), beyond it each column is cut the same way into rows.
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  max_radius_ = 0;
  for (const PlaneBody& body : bodies) {
    const b2Vec2& p = body.body->GetPosition();
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], AlongAxis(p, a));
      hi[a] = std::max(hi[a], AlongAxis(p, a));
    }
    max_radius_ = std::max(max_radius_, PlaneWorld::BoundingRadius(body.body));
  }
  axis_ = hi[0] - lo[0] >= hi[1] - lo[1] ? 0 : 1;
  int64_t columns = count;
  const double length = hi[axis_] - lo[axis_], width = hi[1 - axis_] - lo[1 - axis_];
  if (count > kMaxStrips && width > 0) {
    // Near-square regions: columns / rows as length / width.
    const double ideal = std::sqrt(static_cast<double>(count) * length / width);
    columns = std::clamp<int64_t>(std::llround(ideal), 1, count);
    rows_ = static_cast<int>(std::max<int64_t>(1, count / columns));
  }
  std::vector<double> along;
  along.reserve(bodies.size());
  for (const PlaneBody& body : bodies) along.push_back(AlongAxis(body.body->GetPosition(), axis_));
  std::sort(along.begin(), along.end());
  borders_ = QuantileBorders(along, columns);
  if (rows_ > 1) {
    std::vector<std::vector<double>> across(static_cast<size_t>(columns));
    for (const PlaneBody& body : bodies) {
      const b2Vec2& p = body.body->GetPosition();
      across[static_cast<size_t>(ColumnOf(AlongAxis(p, axis_)))].push_back(AlongAxis(p, 1 - axis_));
    }
    for (std::vector<double>& column : across) {
      std::sort(column.begin(), column.end());
      row_borders_.push_back(QuantileBorders(column, rows_));
    }
  }
  // Each region: the ground fixtures within reach, then its bodies in slot
  // order; the regions are built on every worker (each writes only its own
  // Box2D world and reads the staging one), with the same result as one
  // after the other.
  const double pad = kGroundPad * options_.length_scale + 4 * max_radius_;
  const double infinity = std::numeric_limits<double>::infinity();
  regions_.resize(static_cast<size_t>(columns * rows_));
  ground_reach_.resize(regions_.size());
  std::vector<std::vector<uint32_t>> bodies_of(regions_.size());
  for (uint32_t b = 0; b < bodies.size(); ++b)
    bodies_of[static_cast<size_t>(RegionOf(bodies[b].body->GetPosition()))].push_back(b);
  ForEachRegion([&](size_t index) {
    const int64_t c = static_cast<int64_t>(index) / rows_;
    const int r = static_cast<int>(static_cast<int64_t>(index) % rows_);
    const double column_lo = c == 0 ? -infinity : borders_[static_cast<size_t>(c - 1)];
    const double column_hi = c == columns - 1 ? infinity : borders_[static_cast<size_t>(c)];
    auto region = std::make_unique<PlaneWorld>(options_, settings_);
    region->BuildEmpty();
    double row_lo = -infinity, row_hi = infinity;
    if (rows_ > 1) {
      const std::vector<double>& row_borders = row_borders_[static_cast<size_t>(c)];
      if (r > 0) row_lo = row_borders[static_cast<size_t>(r - 1)];
      if (r < rows_ - 1) row_hi = row_borders[static_cast<size_t>(r)];
    }
    ground_reach_[index] = {column_lo - pad, column_hi + pad, row_lo - pad, row_hi + pad};
    const std::array<double, 4>& reach = ground_reach_[index];
    region->CopyGround(*staging, axis_, reach[0], reach[1], reach[2], reach[3]);
    // Copied, not moved: the staging world goes whole when Build returns.
    for (uint32_t b : bodies_of[index]) staging->CopyBody(b, region.get());
    regions_[index] = std::move(region);
  });
}

void PartitionedPlaneWorld::SyncFromScene(const Scene& scene, double duration) {
  duration_ = duration;
  if (obstacle_poses_.Moved(scene)) MoveObstacles(scene);
  ForEachRegion([&](size_t r) { regions_[r]->SyncFromScene(scene, duration); });
}

void PartitionedPlaneWorld::MoveObstacles(const Scene& scene) {
  obstacle_poses_.MovedSlots(scene, &moved_);
  PlaneWorld moved(options_, settings_);
  moved.BuildEmpty();
  moved.AddShapeObstacles(scene, moved_, dynamic_range_);
  ForEachRegion([&](size_t r) {
    regions_[r]->RemoveShapeObstacles(moved_);
    const std::array<double, 4>& reach = ground_reach_[r];
    regions_[r]->CopyGround(moved, axis_, reach[0], reach[1], reach[2], reach[3]);
  });
  obstacle_poses_.Refresh(scene);
}

void PartitionedPlaneWorld::ReadCommands(const Scene& scene) {
  ForEachRegion([&](size_t r) { regions_[r]->ReadCommands(scene); });
  if (regions_.size() == 1) return;
  Migrate();
  PlaneBodyState* states = states_[current_].data();
  ForEachRegion([&](size_t r) { regions_[r]->PublishStates(states, state_of_slot_.data()); });
  UpdateGhosts();
}

void PartitionedPlaneWorld::Migrate() {
  // Who leaves, found on every worker; the moves in region and body order.
  auto& leaving = leaving_;
  leaving.resize(regions_.size());
  for (auto& list : leaving) list.clear();
  ForEachRegion([&](size_t r) {
    const PlaneWorld& region = *regions_[r];
    for (uint32_t b = 0; b < region.bodies().size(); ++b) {
      const b2Body* body = region.bodies()[b].body;
      if (!body) continue;
      const int to = RegionOf(body->GetPosition());
      if (to != static_cast<int>(r)) leaving[r].emplace_back(b, to);
    }
  });
  bool moved = false;
  for (size_t r = 0; r < regions_.size(); ++r)
    for (const auto& [b, to] : leaving[r]) {
      regions_[r]->MoveBody(b, regions_[static_cast<size_t>(to)].get());
      moved = true;
    }
  if (moved) ForEachRegion([&](size_t r) { regions_[r]->Compact(); });
}

void PartitionedPlaneWorld::UpdateGhosts() {
  // Per region, the ghosts its bodies need elsewhere (region, slot, body),
  // found on every worker; then each region's wanted list, sorted by slot.
  auto& needs = needs_;
  needs.resize(regions_.size());
  for (auto& list : needs) list.clear();
  ForEachRegion([&](size_t r) {
    const PlaneWorld& region = *regions_[r];
    for (uint32_t b = 0; b < region.bodies().size(); ++b) {
      const b2Body* body = region.bodies()[b].body;
      // Its reach: its radius, the largest neighbour's, its travel in the
      // step, and Box2D's broad-phase fattening.
      const double reach = PlaneWorld::BoundingRadius(body) + max_radius_ +
                           kTravelFactor * region.SpeedBound(b) * duration_ + b2_aabbExtension;
      const b2Vec2& p = body->GetPosition();
      const double along = AlongAxis(p, axis_), across = AlongAxis(p, 1 - axis_);
      const int first = ColumnOf(along - reach), last = ColumnOf(along + reach);
      for (int c = first; c <= last; ++c) {
        const int row_first = RowOf(c, across - reach), row_last = RowOf(c, across + reach);
        for (int row = row_first; row <= row_last; ++row) {
          const int t = c * rows_ + row;
          if (t != static_cast<int>(r)) needs[r].push_back({t, {region.bodies()[b].slot, body}});
        }
      }
    }
  });
  auto& wanted = wanted_;
  wanted.resize(regions_.size());
  for (auto& list : wanted) list.clear();
  for (const auto& list : needs)
    for (const auto& [t, want] : list) wanted[static_cast<size_t>(t)].push_back(want);
  ForEachRegion([&](size_t t) {
    std::sort(wanted[t].begin(), wanted[t].end(),
              [](const Want& a, const Want& b) { return a.first < b.first; });
    regions_[t]->SetGhosts(wanted[t]);
  });
}

void PartitionedPlaneWorld::Substep(double dt, double fraction) {
  if (regions_.size() == 1) {
    regions_[0]->Substep(dt, fraction);
    return;
  }
  // Every region: its ghosts to the states published after the last
  // substep, one Box2D step, then its own bodies' states for the next one.
  // Regions only read `in` and write their own slots of `out`: the result
  // does not depend on which worker steps which region, or when.
  const PlaneBodyState* in = states_[current_].data();
  PlaneBodyState* out = states_[1 - current_].data();
  auto step = [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r) {
      PlaneWorld& region = *regions_[r];
      region.RefreshGhosts(in, state_of_slot_.data());
      region.Substep(dt, fraction);
      region.PublishStates(out, state_of_slot_.data());
    }
  };
  const int64_t count = static_cast<int64_t>(regions_.size());
  if (settings_.scheduler)
    settings_.scheduler->ParallelFor(0, count, 1, step);
  else
    step(0, count);
  current_ = 1 - current_;
}

void PartitionedPlaneWorld::WriteBack(Scene* scene) {
  // Each region writes its own bodies' slots.
  ForEachRegion([&](size_t r) { regions_[r]->WriteBack(scene); });
}

void PartitionedPlaneWorld::Hash(StateHasher* hasher) const {
  if (regions_.size() == 1) {  // as one PlaneWorld always hashed
    regions_[0]->Hash(hasher);
    return;
  }
  hasher->AddValue(static_cast<uint32_t>(regions_.size()));
  for (const auto& region : regions_) {
    hasher->AddValue(static_cast<uint32_t>(region->body_count()));
    region->Hash(hasher);
  }
}

int PartitionedPlaneWorld::body_count() const {
  int total = 0;
  for (const auto& region : regions_) total += region->body_count();
  return total;
}

int PartitionedPlaneWorld::ghost_count() const {
  int total = 0;
  for (const auto& region : regions_) total += region->ghost_count();
  return total;
}

}  // namespace swarmsim::box2d
