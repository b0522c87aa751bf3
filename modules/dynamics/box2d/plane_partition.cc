// PartitionedPlaneWorld: regions, migration, ghosts and the concurrent
// substep (see "Partitions" in box2d_backend.h).
#include "modules/dynamics/box2d/plane_partition.h"

#include <box2d/b2_body.h>
#include <box2d/b2_common.h>

#include <algorithm>
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

int PartitionedPlaneWorld::RegionOf(double position) const {
  return static_cast<int>(std::upper_bound(borders_.begin(), borders_.end(), position) -
                          borders_.begin());
}

void PartitionedPlaneWorld::Build(const Scene& scene) {
  auto staging = std::make_unique<PlaneWorld>(options_, settings_);
  staging->Build(scene);
  regions_.clear();
  borders_.clear();
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
    return;
  }
  // Strips across the longer side of the bodies' bounding box, each holding
  // the same number of body centres at Build (borders halfway between two
  // neighbouring centres).
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
  std::vector<double> along;
  along.reserve(bodies.size());
  for (const PlaneBody& body : bodies) along.push_back(AlongAxis(body.body->GetPosition(), axis_));
  std::sort(along.begin(), along.end());
  for (int64_t k = 1; k < count; ++k) {
    const size_t i = static_cast<size_t>(k * body_total / count);
    borders_.push_back(0.5 * (along[i - 1] + along[i]));
  }
  // Each region: the ground fixtures within reach, then its bodies in slot
  // order.
  const double pad = kGroundPad * options_.length_scale + 4 * max_radius_;
  const double infinity = std::numeric_limits<double>::infinity();
  for (int64_t r = 0; r < count; ++r) {
    auto region = std::make_unique<PlaneWorld>(options_, settings_);
    region->BuildEmpty();
    const double region_lo = r == 0 ? -infinity : borders_[r - 1];
    const double region_hi = r == count - 1 ? infinity : borders_[r];
    region->CopyGround(*staging, axis_, region_lo - pad, region_hi + pad);
    regions_.push_back(std::move(region));
  }
  // Copied, not moved: the staging world goes whole when Build returns.
  for (uint32_t b = 0; b < bodies.size(); ++b) {
    const int r = RegionOf(AlongAxis(bodies[b].body->GetPosition(), axis_));
    staging->CopyBody(b, regions_[r].get());
  }
}

void PartitionedPlaneWorld::SyncFromScene(const Scene& scene, double duration) {
  duration_ = duration;
  for (auto& region : regions_) region->SyncFromScene(scene, duration);
}

void PartitionedPlaneWorld::ReadCommands(const Scene& scene) {
  for (auto& region : regions_) region->ReadCommands(scene);
  if (regions_.size() == 1) return;
  Migrate();
  for (auto& region : regions_)
    region->PublishStates(states_[current_].data(), state_of_slot_.data());
  UpdateGhosts();
}

void PartitionedPlaneWorld::Migrate() {
  for (size_t r = 0; r < regions_.size(); ++r) {
    PlaneWorld& region = *regions_[r];
    for (uint32_t b = 0; b < region.bodies().size(); ++b) {
      const b2Body* body = region.bodies()[b].body;
      if (!body) continue;
      const int to = RegionOf(AlongAxis(body->GetPosition(), axis_));
      if (to != static_cast<int>(r)) region.MoveBody(b, regions_[to].get());
    }
  }
  for (auto& region : regions_) region->Compact();
}

void PartitionedPlaneWorld::UpdateGhosts() {
  std::vector<std::vector<std::pair<uint32_t, const b2Body*>>> wanted(regions_.size());
  for (size_t r = 0; r < regions_.size(); ++r) {
    const PlaneWorld& region = *regions_[r];
    for (uint32_t b = 0; b < region.bodies().size(); ++b) {
      const b2Body* body = region.bodies()[b].body;
      // Its reach: its radius, the largest neighbour's, its travel in the
      // step, and Box2D's broad-phase fattening.
      const double reach = PlaneWorld::BoundingRadius(body) + max_radius_ +
                           kTravelFactor * region.SpeedBound(b) * duration_ + b2_aabbExtension;
      const double p = AlongAxis(body->GetPosition(), axis_);
      const int first = RegionOf(p - reach), last = RegionOf(p + reach);
      for (int t = first; t <= last; ++t)
        if (t != static_cast<int>(r)) wanted[t].emplace_back(region.bodies()[b].slot, body);
    }
  }
  for (size_t t = 0; t < regions_.size(); ++t) {
    std::sort(wanted[t].begin(), wanted[t].end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    regions_[t]->SetGhosts(wanted[t]);
  }
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
  for (auto& region : regions_) region->WriteBack(scene);
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
