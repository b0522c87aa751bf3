// IR messaging: who sends, who hears whom, and what.
//
// Each sense phase (dt the world's time step):
// 1. one pass over the transceivers clears what each heard and sent, and
//    lists the queued messages (a queue empties whether its message goes
//    out or not);
// 2. each queued message gets a start time t, uniform in [0, dt - p) (p its
//    packet_time; [0, dt) when p >= dt), from the sender's stream; it would
//    be on the air in [t, t + p);
// 3. carrier sense, in the order of start times (then the slot): a sender
//    with carrier_sense defers if it hears a message already gone out that
//    started strictly before it and is still on the air at t (its origin
//    within the sender's own range of that sender's, another robot's):
//    nothing goes out, and `sent` stays false. Otherwise it goes out.
//    (Two messages starting at the very same instant both go out.)
// 4. every transceiver, in parallel (each writes only its own row), lists
//    the messages gone out from within its own range (3D, closed: a sender
//    at exactly `range` is heard), other robots' only, in the order of start
//    times; with failure_probability it hears nothing this step; with
//    `collisions`, a message that overlaps in time another one it lists, or
//    its own transmission (half duplex), is lost; then each is lost with
//    loss_probability; the others arrive, each with the sender's bytes and
//    the distance between the two origins plus N(0, distance_noise),
//    clamped to >= 0.
// Robots, walls and the map do not block: the light goes through the floor.
// Messages of one step meet only one another (with p < dt none overruns its
// step). Every draw comes from framework/sensor_noise.h's streams keyed by
// (seed, slot, step, purpose): start times from the sender's (kIrTransmit),
// a receiver's failure, then its losses and noise in arrival order, from its
// own (kIrReceive). Nothing depends on the grid, the thread count or which
// worker ran which transceiver. Cost: the pass of step 1, then a grid
// lookup per transceiver, then work per (transmission, receiver in range).
#include "modules/ir_messaging/module.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/sensor_noise.h"
#include "framework/world.h"

namespace swarmsim::ir_messaging {

namespace {

// Transceivers per task: an idle one costs a grid lookup.
constexpr int64_t kRowGrain = 256;
// At most this many grid cells per transmission (coarser cells beyond).
constexpr double kMaxCellsPerItem = 4;

}  // namespace

void IrMessagingModule::Grid::Build(const std::vector<Transmission>& t, double cell) {
  cells_x = cells_y = 0;
  start.clear();
  points.clear();
  if (t.empty()) return;
  double x1 = -INFINITY, y1 = -INFINITY;
  x0 = INFINITY, y0 = INFINITY;
  for (const Transmission& m : t) {
    x0 = std::min(x0, m.x), y0 = std::min(y0, m.y);
    x1 = std::max(x1, m.x), y1 = std::max(y1, m.y);
  }
  // Cells of at least `cell`, and not many more than the items.
  const double w = x1 - x0, h = y1 - y0;
  const double max_cells = kMaxCellsPerItem * static_cast<double>(t.size()) + 16;
  if ((w / cell + 1) * (h / cell + 1) > max_cells)
    cell = std::max(cell, std::sqrt(w * h / max_cells) + std::max(w, h) / max_cells);
  inv_cell = 1 / cell;
  cells_x = static_cast<int>(w * inv_cell) + 1;
  cells_y = static_cast<int>(h * inv_cell) + 1;
  const size_t cells = static_cast<size_t>(cells_x) * static_cast<size_t>(cells_y);
  start.assign(cells + 1, 0);
  const auto cell_of = [&](const Transmission& m) {
    const int ix = std::min(cells_x - 1, static_cast<int>((m.x - x0) * inv_cell));
    const int iy = std::min(cells_y - 1, static_cast<int>((m.y - y0) * inv_cell));
    return static_cast<size_t>(iy) * static_cast<size_t>(cells_x) + static_cast<size_t>(ix);
  };
  for (const Transmission& m : t) ++start[cell_of(m) + 1];
  for (size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  points.resize(t.size());
  fill_.assign(start.begin(), start.end() - 1);
  for (size_t i = 0; i < t.size(); ++i)
    points[fill_[cell_of(t[i])]++] = {t[i].x, t[i].y, t[i].z, static_cast<uint32_t>(i)};
}

template <class Visit>
void IrMessagingModule::Grid::Near(double x, double y, Visit&& visit) const {
  if (cells_x == 0) return;
  const double fx = std::floor((x - x0) * inv_cell), fy = std::floor((y - y0) * inv_cell);
  // Also false for NaN: a transceiver nowhere hears nothing.
  if (!(fx >= -1 && fx <= cells_x && fy >= -1 && fy <= cells_y)) return;
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const int x_lo = std::max(0, ix - 1), x_hi = std::min(cells_x - 1, ix + 1);
  const int y_lo = std::max(0, iy - 1), y_hi = std::min(cells_y - 1, iy + 1);
  for (int cy = y_lo; cy <= y_hi; ++cy) {
    const size_t row = static_cast<size_t>(cy) * static_cast<size_t>(cells_x);
    for (size_t e = start[row + x_lo]; e < start[row + x_hi + 1]; ++e) visit(points[e]);
  }
}

void IrMessagingModule::Transmit(double time_step) {
  // 2. Start times, from each sender's stream; then in that order.
  for (Transmission& m : queued_) {
    const IrSettings& s = *scene_rows_->rows[m.row].settings;
    const double p = s.packet_time;
    const double window = p < time_step ? time_step - p : time_step;
    Rng rng = NoiseStream(seed_, m.slot, step_, NoisePurpose::kIrTransmit);
    m.start = rng.Uniform() * window;
    m.end = m.start + p;
  }
  std::sort(queued_.begin(), queued_.end(), [](const Transmission& a, const Transmission& b) {
    return a.start != b.start ? a.start < b.start : a.slot < b.slot;
  });
  // 3. Carrier sense, in that order: each sender looks at those before it
  // that went out.
  grid_.Build(queued_, max_range_);
  on_air_.clear();
  went_out_.assign(queued_.size(), 0);
  for (size_t i = 0; i < queued_.size(); ++i) {
    const Transmission& m = queued_[i];
    bool busy = false;
    if (m.carrier_sense) {
      const double range2 = m.range * m.range;
      grid_.Near(m.x, m.y, [&](const Grid::Point& point) {
        const uint32_t j = point.index;
        if (busy || j >= i || went_out_[j] == 0) return;
        const Transmission& o = queued_[j];
        if (!(o.start < m.start && m.start < o.end)) return;
        if (m.instance >= 0 ? o.instance == m.instance : o.slot == m.slot) return;
        const double dx = o.x - m.x, dy = o.y - m.y, dz = o.z - m.z;
        busy = dx * dx + dy * dy + dz * dz <= range2;
      });
    }
    if (busy) continue;
    went_out_[i] = 1;
    on_air_.push_back(m);
    scene_rows_->rows[m.row].sent = true;
  }
  grid_.Build(on_air_, max_range_);
}

void IrMessagingModule::Hear(const Scene& scene, const Rows<IrTransceiverRow>& rows, uint32_t row,
                             IrTransceiverRow* ir) const {
  const uint32_t slot = rows.owners[row];
  const Vec3& p = scene.world_pose_at(slot).p;
  const IrSettings& s = *ir->settings;
  const double range2 = s.range * s.range;
  const int instance = scene.instance_of_at(slot);
  thread_local std::vector<Heard> heard;
  heard.clear();
  // Its own transmission, if it went out (half duplex).
  double own_start = 0, own_end = 0;
  bool own = false;
  grid_.Near(p.x, p.y, [&](const Grid::Point& point) {
    const double dx = point.x - p.x, dy = point.y - p.y, dz = point.z - p.z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 > range2) return;  // also its own: at distance 0, always in range
    const Transmission& m = on_air_[point.index];
    if (m.slot == slot) {
      own = true, own_start = m.start, own_end = m.end;
      return;
    }
    if (instance >= 0 && m.instance == instance) return;  // a robot never hears itself
    heard.push_back({point.index, std::sqrt(d2)});
  });
  if (heard.empty()) return;
  // Arrival order (on_air_ is by start time); a few items: insertion sort.
  for (size_t k = 1; k < heard.size(); ++k)
    for (size_t j = k; j > 0 && heard[j].index < heard[j - 1].index; --j)
      std::swap(heard[j], heard[j - 1]);
  const bool draws = s.failure_probability > 0 || s.loss_probability > 0 || s.distance_noise > 0;
  Rng rng = draws ? NoiseStream(seed_, slot, step_, NoisePurpose::kIrReceive) : Rng();
  if (s.failure_probability > 0 && rng.Uniform() < s.failure_probability) return;
  // Collisions: a message overlapping an earlier one (the latest end so
  // far), the next one, or the receiver's own transmission is lost.
  size_t kept = 0;
  double end_before = -INFINITY;
  for (size_t k = 0; k < heard.size(); ++k) {
    const Transmission& m = on_air_[heard[k].index];
    bool lost = false;
    if (s.collisions) {
      lost = m.start < end_before ||
             (k + 1 < heard.size() && on_air_[heard[k + 1].index].start < m.end) ||
             (own && m.start < own_end && own_start < m.end);
      end_before = std::max(end_before, m.end);
    }
    if (!lost) heard[kept++] = heard[k];
  }
  heard.resize(kept);
  // Losses and the distance estimates, in arrival order.
  size_t bytes = 0;
  for (const Heard& h : heard) bytes += rows.rows[on_air_[h.index].row].outgoing.size();
  ir->received.resize(bytes);
  ir->inbox.reserve(heard.size());
  uint32_t offset = 0;
  for (const Heard& h : heard) {
    if (s.loss_probability > 0 && rng.Uniform() < s.loss_probability) continue;
    const Transmission& m = on_air_[h.index];
    double distance = h.distance;
    if (s.distance_noise > 0) distance = std::max(0.0, distance + rng.Normal(0, s.distance_noise));
    const std::vector<uint8_t>& data = rows.rows[m.row].outgoing;
    if (!data.empty()) std::memcpy(ir->received.data() + offset, data.data(), data.size());
    ir->inbox.push_back({distance, scene.IdAt(m.slot), offset, static_cast<uint32_t>(data.size())});
    offset += static_cast<uint32_t>(data.size());
  }
  ir->received.resize(offset);
}

IrTransceiverRow* IrMessagingModule::Find(const Scene& scene, ObjectId id) const noexcept {
  if (!have_type_ || !scene.IsValid(id) || scene.type(id) != type_) return nullptr;
  // The plugins' C API hands out the scene as mutable (ir_send); reads stay reads.
  auto& rows = const_cast<Scene&>(scene).rows<IrTransceiverRow>(type_);
  return &rows.rows[scene.row_at(scene.SlotOf(id))];
}

int IrMessagingModule::Send(Scene* scene, int robot, ObjectId id, const uint8_t* data,
                            size_t size) const noexcept {
  IrTransceiverRow* ir = Find(*scene, id);
  if (ir == nullptr || robot < 0 || scene->instance_of(id) != robot ||
      size > ir->settings->payload_size || (data == nullptr && size > 0))
    return -1;
  try {
    ir->outgoing.assign(data, data + size);  // at most kMaxPayloadSize bytes
  } catch (const std::exception&) {
    return -1;  // out of memory
  }
  ir->queued = true;
  return 0;
}

int IrMessagingModule::Sent(const Scene& scene, ObjectId id) const noexcept {
  const IrTransceiverRow* ir = Find(scene, id);
  return ir == nullptr ? -1 : (ir->sent ? 1 : 0);
}

int IrMessagingModule::Receive(const Scene& scene, ObjectId id, SwarmsimIrMessage* out,
                               int max) const noexcept {
  const IrTransceiverRow* ir = Find(scene, id);
  if (ir == nullptr) return -1;
  const int count = static_cast<int>(ir->inbox.size());
  for (int i = 0; i < count && i < max; ++i) {
    const IrReceived& r = ir->inbox[static_cast<size_t>(i)];
    out[i] = {ir->received.data() + r.data_offset, r.data_size, r.distance};
  }
  return count;
}

void IrMessagingModule::Start(World* world) {
  have_type_ = world->scene().FindType(kTypeName, &type_);
}

void IrMessagingModule::Sense(World* world) {
  Scene& scene = world->scene();
  if (!have_type_) return;
  auto& rows = scene.rows<IrTransceiverRow>(type_);
  if (rows.size() == 0) return;
  scene_rows_ = &rows;
  seed_ = world->settings().seed;
  step_ = world->step_count();
  // 1. Clear last step's, list the queued messages and the largest range.
  queued_.clear();
  max_range_ = 0;
  const IrSettings* last = nullptr;  // copies share settings: read each block once
  for (size_t r = 0; r < rows.size(); ++r) {
    IrTransceiverRow& ir = rows.rows[r];
    ir.sent = false;
    ir.inbox.clear();
    ir.received.clear();
    const IrSettings* s = &*ir.settings;
    if (s != last) max_range_ = std::max(max_range_, s->range), last = s;
    if (!ir.queued) continue;
    ir.queued = false;
    const uint32_t slot = rows.owners[r];
    const Vec3& p = scene.world_pose_at(slot).p;
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    queued_.push_back({p.x, p.y, p.z, 0, 0, s->range, scene.instance_of_at(slot), slot,
                       static_cast<uint32_t>(r), s->carrier_sense});
  }
  if (queued_.empty()) return;
  Transmit(world->settings().time_step);
  // 4. Every transceiver's inbox, in parallel.
  world->scheduler().ParallelFor(0, static_cast<int64_t>(rows.size()), kRowGrain,
                                 [&](int64_t begin, int64_t end) {
                                   for (int64_t r = begin; r < end; ++r)
                                     Hear(scene, rows, static_cast<uint32_t>(r), &rows.rows[r]);
                                 });
}

}  // namespace swarmsim::ir_messaging
