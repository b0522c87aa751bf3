// Range-and-bearing boards: who hears whom, and what.
//
// Each sense phase:
// 1. every board's origin goes into a 2D grid over its (x, y);
// 2. if a board tests occlusion, every shape of no robot (static or not)
//    that reaches the boards' heights is placed at its pose and goes into
//    a grid, its (x, y) bounds as a circle (walls longer than a cell go to
//    the grid's short list every query scans); if a board tests robot
//    occlusion, every robot's shape goes into another;
// 3. every board, in parallel (each writes only its own row):
//    - with failure_probability, it hears nothing this step (a draw);
//    - the boards of the grid cells within its range, minus those of its
//      own robot (a board of no robot: minus itself), within range in 3D,
//      sorted by distance, then by the sender's slot (handle order);
//    - nearest first, each is tested for occlusion: the segment between the
//      two boards' origins against the shapes listed once per receiver
//      (those whose bounds meet its range's box at the boards' heights;
//      bounding box first, then modules/proximity/ray_cast.h's exact test)
//      and against the environment map's voxels (the world's line of
//      sight), with `occlusion`; against the robots' shapes but the two
//      boards' own, with `robot_occlusion`; then lost with probability
//      min(1, loss_probability + loss_at_range (d / range)^2);
//    - with `capacity` and `nearest`, the first `capacity` that pass are
//      kept (and the rest are not tested); with `random`, `capacity` of
//      those that pass are drawn without replacement, kept in the nearest-
//      first order;
//    - each kept reading gets its range, bearing and elevation in the
//      receiver board's frame, then its noise, and its sender's payload.
// Every draw comes from framework/sensor_noise.h's streams keyed by (seed,
// the receiving board's slot, step, purpose), in the nearest-first order
// above: nothing depends on the grid, the thread count or which worker ran
// which board. A board without loss, noise, failure or random capacity
// draws nothing.
#include "modules/range_and_bearing/module.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "framework/environment.h"
#include "framework/line_of_sight.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/world.h"

namespace swarmsim::range_and_bearing {

namespace {

constexpr double kPi = 3.141592653589793;
constexpr double kTwoPi = 6.283185307179586;
// The occlusion segment stops this short of each board (m), so that a
// shape a board sits on the surface of does not block it.
constexpr double kEndMargin = 1e-6;
// Boards per task: a board costs about a microsecond.
constexpr int64_t kBoardGrain = 32;

// An angle in (-pi, pi].
double Wrap(double a) {
  a = std::remainder(a, kTwoPi);
  return a == -kPi ? kPi : a;
}

}  // namespace

void RangeAndBearingModule::IndexBoards(const Scene& scene, const Rows<RangeAndBearingRow>& rows) {
  boards_.resize(rows.size());
  board_items_.resize(rows.size());
  z_lo_ = INFINITY, z_hi_ = -INFINITY;
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint32_t slot = rows.owners[r];
    const Vec3& p = scene.world_pose_at(slot).p;
    boards_[r] = {p, scene.instance_of_at(slot), slot, static_cast<uint32_t>(r)};
    board_items_[r] = {p.x, p.y, 0, static_cast<uint32_t>(r)};
    z_lo_ = std::min(z_lo_, p.z), z_hi_ = std::max(z_hi_, p.z);
  }
  board_grid_.Build(board_items_);
}

void RangeAndBearingModule::IndexShapes(const Scene& scene, bool statics, bool robots) {
  for (ShapeIndex* index : {&statics_, &robot_shapes_}) {
    index->shapes.clear();
    index->items.clear();
  }
  const auto shapes = scene.shapes();
  const auto owners = scene.shape_owners();
  for (size_t r = 0; r < shapes.size(); ++r) {
    const uint32_t slot = owners[r];
    const int instance = scene.instance_of_at(slot);
    ShapeIndex* index =
        instance >= 0 ? (robots ? &robot_shapes_ : nullptr) : (statics ? &statics_ : nullptr);
    if (index == nullptr) continue;
    Occluder o;
    o.shape =
        proximity::PlaceShape(shapes[r], scene.world_pose_at(slot), scene.IdAt(slot), instance);
    o.slot = slot;
    proximity::WorldBounds(o.shape, &o.lo, &o.hi);
    // Grown a little: the exact test decides, these only must not miss.
    const double margin = 1e-9 * (1 + std::abs(o.lo.x) + std::abs(o.lo.y) + std::abs(o.lo.z) +
                                  std::abs(o.hi.x) + std::abs(o.hi.y) + std::abs(o.hi.z));
    o.lo = o.lo - Vec3{margin, margin, margin};
    o.hi = o.hi + Vec3{margin, margin, margin};
    // No segment between two boards leaves their heights.
    if (o.hi.z < z_lo_ || o.lo.z > z_hi_) continue;
    o.cx = 0.5 * (o.lo.x + o.hi.x), o.cy = 0.5 * (o.lo.y + o.hi.y);
    o.r = 0.5 * std::hypot(o.hi.x - o.lo.x, o.hi.y - o.lo.y);
    index->items.push_back({o.cx, o.cy, o.r, static_cast<uint32_t>(index->shapes.size())});
    index->shapes.push_back(o);
  }
  for (ShapeIndex* index : {&statics_, &robot_shapes_})
    if (!index->items.empty()) index->grid.Build(index->items);
}

template <class Skip>
void RangeAndBearingModule::ShapeIndex::List(double x, double y, double r, double z_lo, double z_hi,
                                             Skip skip, std::vector<uint32_t>* out) const {
  out->clear();
  if (items.empty()) return;
  grid.QueryCircle(x, y, r, out);
  size_t kept = 0;
  for (uint32_t j : *out) {
    const Occluder& o = shapes[j];
    if (o.hi.x < x - r || o.lo.x > x + r || o.hi.y < y - r || o.lo.y > y + r || o.hi.z < z_lo ||
        o.lo.z > z_hi || skip(o))
      continue;
    (*out)[kept++] = j;
  }
  out->resize(kept);
}

bool RangeAndBearingModule::Blocked(const Scene& scene, const Board& from, const Board& to,
                                    double distance, const std::vector<Footprint>& statics,
                                    bool map, const std::vector<Footprint>& robots) const {
  const double length = distance - 2 * kEndMargin;
  if (!(length > 0)) return false;
  const Vec3 d_W = (to.p_W - from.p_W) / distance;
  const Vec3 start = from.p_W + d_W * kEndMargin;
  const Vec3 v_W = d_W * length;
  double hit = 0;
  // Does the segment's (x, y) pass within o's footprint circle? A cheap
  // first test for the robots' bodies and the walls far to one side.
  const double inv_len2 = 1 / (v_W.x * v_W.x + v_W.y * v_W.y);
  const bool planar = std::isfinite(inv_len2);
  const auto near = [&](const Footprint& f) {
    const double ex = f.cx - start.x, ey = f.cy - start.y;
    const double t = planar ? std::clamp((ex * v_W.x + ey * v_W.y) * inv_len2, 0.0, 1.0) : 0;
    const double dx = ex - t * v_W.x, dy = ey - t * v_W.y;
    return dx * dx + dy * dy <= f.r2;
  };
  const proximity::Segment segment(start, v_W);
  for (const Footprint& f : statics) {
    if (!near(f)) continue;
    const Occluder& o = statics_.shapes[f.shape];
    if (!segment.MeetsBox(o.lo, o.hi)) continue;
    // A board of no robot is not blocked by the shapes it hangs from.
    if (to.instance < 0 && scene.IsAbove(o.slot, to.slot)) continue;
    if (proximity::RayCast(o.shape, start, d_W, length, &hit)) return true;
  }
  for (const Footprint& f : robots) {
    if (!near(f)) continue;
    const Occluder& o = robot_shapes_.shapes[f.shape];
    if (!segment.MeetsBox(o.lo, o.hi)) continue;
    // The sender's own shapes never block it (the receiver's were left out).
    if (to.instance >= 0 ? o.shape.instance == to.instance : scene.IsAbove(o.slot, to.slot))
      continue;
    if (proximity::RayCast(o.shape, start, d_W, length, &hit)) return true;
  }
  return map && line_of_sight_->SegmentBlocked(start, start + v_W);
}

void RangeAndBearingModule::Hear(const Scene& scene, const Rows<RangeAndBearingRow>& rows,
                                 uint32_t row, RangeAndBearingRow* rab) const {
  const RangeAndBearingSettings& s = *rab->settings;
  rab->readings.clear();
  rab->received.clear();
  const Board& self = boards_[row];
  // A board that fails hears nothing this step.
  if (s.range_noise.failure > 0) {
    Rng fail = NoiseStream(seed_, self.slot, step_, NoisePurpose::kRangeAndBearingLoss);
    if (Fails(s.range_noise, fail)) return;
  }
  // The boards in range, nearest first.
  thread_local std::vector<uint32_t> near, statics, robots;
  thread_local std::vector<Footprint> static_footprints, robot_footprints;
  thread_local std::vector<Heard> heard;
  board_grid_.QueryCircle(self.p_W.x, self.p_W.y, s.range, &near);
  heard.clear();
  const double range2 = s.range * s.range;
  for (uint32_t i : near) {
    const Board& other = boards_[i];
    if (i == row || (self.instance >= 0 && other.instance == self.instance)) continue;
    const double d2 = (other.p_W - self.p_W).SquaredNorm();
    if (!(d2 <= range2)) continue;
    heard.push_back({std::sqrt(d2), i});
  }
  if (heard.empty()) return;
  std::sort(heard.begin(), heard.end(), [this](const Heard& a, const Heard& b) {
    return a.distance != b.distance ? a.distance < b.distance
                                    : boards_[a.board].slot < boards_[b.board].slot;
  });
  // Occlusion, loss and capacity, nearest first. The shapes that may
  // block: those near the receiver at the boards' heights, but its own.
  statics.clear();
  robots.clear();
  if (s.occlusion && have_statics_)
    statics_.List(
        self.p_W.x, self.p_W.y, s.range, z_lo_, z_hi_,
        [&](const Occluder& o) { return self.instance < 0 && scene.IsAbove(o.slot, self.slot); },
        &statics);
  if (s.robot_occlusion && have_robot_shapes_)
    robot_shapes_.List(
        self.p_W.x, self.p_W.y, s.range, z_lo_, z_hi_,
        [&](const Occluder& o) {
          return self.instance >= 0 ? o.shape.instance == self.instance
                                    : scene.IsAbove(o.slot, self.slot);
        },
        &robots);
  // Their footprints, packed for the test of each segment.
  const auto pack = [](const ShapeIndex& index, const std::vector<uint32_t>& listed,
                       std::vector<Footprint>* out) {
    out->clear();
    for (uint32_t j : listed) {
      const Occluder& o = index.shapes[j];
      out->push_back({o.cx, o.cy, o.r * o.r, j});
    }
  };
  pack(statics_, statics, &static_footprints);
  pack(robot_shapes_, robots, &robot_footprints);
  const bool map = s.occlusion && have_map_;
  const bool occluded = map || !statics.empty() || !robots.empty();
  const bool lossy = s.loss_probability > 0 || s.loss_at_range > 0;
  Rng loss =
      lossy ? NoiseStream(seed_, self.slot, step_, NoisePurpose::kRangeAndBearingLoss) : Rng();
  if (lossy && s.range_noise.failure > 0) loss.Uniform();  // the failure's draw, as above
  const size_t capacity =
      s.capacity > 0 && s.capacity_order == CapacityOrder::kNearest ? s.capacity : heard.size();
  size_t kept = 0;
  for (size_t k = 0; k < heard.size() && kept < capacity; ++k) {
    const Board& other = boards_[heard[k].board];
    if (occluded &&
        Blocked(scene, self, other, heard[k].distance, static_footprints, map, robot_footprints))
      continue;
    if (lossy) {
      const double p = s.LossAt(heard[k].distance);
      if (p > 0 && loss.Uniform() < p) continue;
    }
    heard[kept++] = heard[k];
  }
  heard.resize(kept);
  // A random `capacity` of them, in the same order.
  if (s.capacity > 0 && s.capacity_order == CapacityOrder::kRandom && heard.size() > s.capacity) {
    Rng pick = NoiseStream(seed_, self.slot, step_, NoisePurpose::kCapacity);
    for (size_t k = 0; k < s.capacity; ++k)
      std::swap(heard[k], heard[static_cast<size_t>(pick.UniformInt(
                              static_cast<int64_t>(k), static_cast<int64_t>(heard.size()) - 1))]);
    heard.resize(s.capacity);
    std::sort(heard.begin(), heard.end(), [this](const Heard& a, const Heard& b) {
      return a.distance != b.distance ? a.distance < b.distance
                                      : boards_[a.board].slot < boards_[b.board].slot;
    });
  }
  // The readings, in the receiver's frame, with their noise and payloads.
  const Quat q_RW = scene.world_pose_at(self.slot).q.Conjugate();
  const bool noisy = s.range_noise.perturbs() || s.bearing_noise.perturbs();
  Rng noise = noisy ? NoiseStream(seed_, self.slot, step_, NoisePurpose::kRangeAndBearing) : Rng();
  size_t bytes = 0;
  for (const Heard& h : heard) bytes += rows.rows[boards_[h.board].row].settings->payload_size;
  rab->received.assign(bytes, 0);
  rab->readings.resize(heard.size());
  uint32_t offset = 0;
  for (size_t k = 0; k < heard.size(); ++k) {
    const Board& other = boards_[heard[k].board];
    const RangeAndBearingRow& sender = rows.rows[other.row];
    const Vec3 d_R = q_RW.Rotate(other.p_W - self.p_W);
    RangeAndBearingReading& reading = rab->readings[k];
    reading.range = heard[k].distance;
    reading.bearing = std::atan2(d_R.y, d_R.x);
    if (reading.bearing == -kPi) reading.bearing = kPi;  // (-pi, pi]: straight behind is +pi
    // Boards at one height (the usual case) spare an atan2.
    reading.elevation =
        d_R.z == 0 ? 0 : std::atan2(d_R.z, std::sqrt(d_R.x * d_R.x + d_R.y * d_R.y));
    if (noisy) {
      if (s.range_noise.perturbs())
        reading.range = std::max(0.0, Perturb(s.range_noise, reading.range, noise));
      if (s.bearing_noise.perturbs()) {
        reading.bearing = Wrap(Perturb(s.bearing_noise, reading.bearing, noise));
        reading.elevation =
            std::clamp(Perturb(s.bearing_noise, reading.elevation, noise), -0.5 * kPi, 0.5 * kPi);
      }
    }
    reading.sender = scene.IdAt(other.slot);
    // Its payload: what the sender set, then zeros up to its payload size.
    const uint32_t size = sender.settings->payload_size;
    reading.data_offset = offset;
    reading.data_size = size;
    const size_t set = std::min<size_t>(sender.data.size(), size);
    if (set > 0) std::memcpy(rab->received.data() + offset, sender.data.data(), set);
    offset += size;
  }
}

int RangeAndBearingModule::SetData(Scene* scene, int robot, ObjectId id, const uint8_t* data,
                                   size_t size) const noexcept {
  ObjectType type;
  if (!scene->FindType(kTypeName, &type) || !scene->IsValid(id) || scene->type(id) != type ||
      robot < 0 || scene->instance_of(id) != robot)
    return -1;
  RangeAndBearingRow& rab =
      scene->rows<RangeAndBearingRow>(type).rows[scene->row_at(scene->SlotOf(id))];
  if (size > rab.settings->payload_size) return -1;
  try {
    rab.data.assign(data, data + size);  // at most kMaxPayloadSize bytes
  } catch (const std::exception&) {
    return -1;  // out of memory
  }
  return 0;
}

int RangeAndBearingModule::Read(const Scene& scene, ObjectId id,
                                SwarmsimRangeAndBearingReading* out, int max) const noexcept {
  ObjectType type;
  if (!scene.FindType(kTypeName, &type) || !scene.IsValid(id) || scene.type(id) != type) return -1;
  const RangeAndBearingRow& rab =
      scene.rows<RangeAndBearingRow>(type).rows[scene.row_at(scene.SlotOf(id))];
  const int count = static_cast<int>(rab.readings.size());
  for (int i = 0; i < count && i < max; ++i) {
    const RangeAndBearingReading& r = rab.readings[static_cast<size_t>(i)];
    out[i] = {rab.received.data() + r.data_offset, r.data_size, r.range, r.bearing, r.elevation};
  }
  return count;
}

void RangeAndBearingModule::Sense(World* world) {
  Scene& scene = world->scene();
  if (!type_found_) {
    have_type_ = scene.FindType(kTypeName, &type_);
    type_found_ = true;
  }
  if (!have_type_) return;
  auto& rows = scene.rows<RangeAndBearingRow>(type_);
  if (rows.size() == 0) return;
  seed_ = world->settings().seed;
  step_ = world->step_count();
  line_of_sight_ = world->line_of_sight();
  const EnvironmentMap* environment = scene.environment();
  have_map_ = line_of_sight_ != nullptr && environment != nullptr && !environment->boxes.empty();
  IndexBoards(scene, rows);
  bool statics = false, robots = false;
  for (const RangeAndBearingRow& rab : rows.rows) {
    statics |= rab.settings->occlusion;
    robots |= rab.settings->robot_occlusion;
  }
  if (statics || robots) IndexShapes(scene, statics, robots);
  have_statics_ = statics && !statics_.items.empty();
  have_robot_shapes_ = robots && !robot_shapes_.items.empty();
  world->scheduler().ParallelFor(0, static_cast<int64_t>(rows.size()), kBoardGrain,
                                 [&](int64_t begin, int64_t end) {
                                   for (int64_t r = begin; r < end; ++r)
                                     Hear(scene, rows, static_cast<uint32_t>(r), &rows.rows[r]);
                                 });
}

}  // namespace swarmsim::range_and_bearing
