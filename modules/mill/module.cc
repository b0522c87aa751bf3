#include "modules/mill/module.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "modules/mill/rows.h"

namespace swarmsim::mill {

namespace {

// Robots per task: a mill's search costs more than a sensor's reading.
constexpr int64_t kMillGrain = 2;

Vec3 Min(const Vec3& a, const Vec3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
Vec3 Max(const Vec3& a, const Vec3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

// Voxel indices [first, last] along an axis of n voxels of `edge` starting
// at `start` whose centres lie in [lo, hi]; first > last when none (also
// for NaN bounds: nothing is cast before it is clamped).
void VoxelRange(double start, double edge, uint32_t n, double lo, double hi, int64_t* first,
                int64_t* last) {
  const double f = std::ceil((lo - start) / edge - 0.5);
  const double l = std::floor((hi - start) / edge - 0.5);
  if (!(f <= l) || !(l >= 0) || !(f < n)) {
    *first = 1;
    *last = 0;
    return;
  }
  *first = static_cast<int64_t>(std::max(f, 0.0));
  *last = static_cast<int64_t>(std::min(l, static_cast<double>(n) - 1));
}

}  // namespace

void MillModule::Refresh(Scene* scene) {
  version_ = scene->structure_version();
  if (!have_types_)
    have_types_ =
        scene->FindType("mill", &mill_type_) && scene->FindType("cuttable", &cuttable_type_);
  any_mills_ = false;
  if (!have_types_) return;
  const auto& mills = static_cast<const Rows<MillRow>&>(*scene->rows(mill_type_));
  mills_.assign(scene->instances().size() + 1, {});
  for (uint32_t r = 0; r < mills.size(); ++r) {
    const int instance = scene->instance_of_at(mills.owners[r]);
    mills_[instance >= 0 ? instance : mills_.size() - 1].push_back(r);
  }
  any_mills_ = mills.size() > 0;
  found_.assign(mills.size(), {});
  // The blocks' bits, counted before any is allocated.
  const auto& cuttables = static_cast<const Rows<CuttableRow>&>(*scene->rows(cuttable_type_));
  double voxels = 0;
  for (const CuttableRow& c : cuttables.rows) voxels += static_cast<double>(c.voxel_count());
  if (any_mills_ && voxels > kMaxWorldVoxels) {
    char message[200];
    std::snprintf(message, sizeof message,
                  "the world's %zu cuttable blocks hold %.0f voxels together, more than %.0f "
                  "(%.1f GB); use coarser resolutions or fewer blocks",
                  cuttables.size(), voxels, kMaxWorldVoxels, voxels / 8e9);
    throw Error(message);
  }
}

// Each cuttable's bits (a new object gets a full block) and bounding sphere.
void MillModule::EnsureBlocks(Scene* scene) {
  const auto& cuttables = static_cast<const Rows<CuttableRow>&>(*scene->rows(cuttable_type_));
  blocks_.resize(std::max<size_t>(blocks_.size(), scene->slot_count()));
  centres_.resize(cuttables.size());
  radii_.resize(cuttables.size());
  items_.resize(cuttables.size());
  for (uint32_t r = 0; r < cuttables.size(); ++r) {
    const uint32_t slot = cuttables.owners[r];
    const CuttableRow& c = cuttables.rows[r];
    const uint64_t id = static_cast<uint64_t>(scene->IdAt(slot).ToInteger());
    const size_t words = static_cast<size_t>((c.voxel_count() + 63) / 64);
    std::unique_ptr<Block>& block = blocks_[slot];
    if (block == nullptr || block->id != id || block->bits.size() != words) {
      block = std::make_unique<Block>();
      block->id = id;
      block->bits.assign(words, ~uint64_t{0});
      if (const int tail = static_cast<int>(c.voxel_count() % 64); tail != 0)
        block->bits.back() = (uint64_t{1} << tail) - 1;
    }
    centres_[r] = scene->world_pose_at(slot).p;
    radii_[r] = c.size.Norm() / 2;
    items_[r] = {centres_[r].x, centres_[r].y, radii_[r], r};
  }
  grid_.Build(items_);
}

// The voxels (still there) of every cuttable near the mill whose centres
// are inside its volume. Reads only: robots run this concurrently.
void MillModule::Find(const Scene& scene, uint32_t mill_row) {
  const auto& mills = static_cast<const Rows<MillRow>&>(*scene.rows(mill_type_));
  const auto& cuttables = static_cast<const Rows<CuttableRow>&>(*scene.rows(cuttable_type_));
  std::vector<Found>& found = found_[mill_row];
  found.clear();
  const MillRow& m = mills.rows[mill_row];
  if (!m.enabled) return;
  const Pose& X_WM = scene.world_pose_at(mills.owners[mill_row]);
  Vec3 lo_M, hi_M;
  Bounds(m.volume, &lo_M, &hi_M);
  const Vec3 centre_W = X_WM * ((lo_M + hi_M) * 0.5);
  const double radius = (hi_M - lo_M).Norm() / 2;
  // Cuttables in ascending row order (the grid's), spheres meeting the volume's.
  grid_.ForEachInCircle(centre_W.x, centre_W.y, radius, [&](uint32_t c, const GridItem&) {
    if ((centre_W - centres_[c]).Norm() > radius + radii_[c]) return;
    const Pose X_CM = scene.world_pose_at(cuttables.owners[c]).Inverse() * X_WM;
    Found f{c, {}};
    FindIn(cuttables.rows[c], *blocks_[cuttables.owners[c]], m.volume, X_CM, &f.voxels);
    if (!f.voxels.empty()) found.push_back(std::move(f));
  });
}

void MillModule::FindIn(const CuttableRow& cut, const Block& block, const Volume& volume,
                        const Pose& X_CM, std::vector<uint32_t>* voxels) {
  // The volume's bounds in the block's frame, then the voxels there.
  Vec3 lo_M, hi_M;
  Bounds(volume, &lo_M, &hi_M);
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < 8; ++k) {
    const Vec3 p =
        X_CM * Vec3{k & 1 ? hi_M.x : lo_M.x, k & 2 ? hi_M.y : lo_M.y, k & 4 ? hi_M.z : lo_M.z};
    lo = Min(lo, p);
    hi = Max(hi, p);
  }
  const Pose X_MC = X_CM.Inverse();
  const Vec3 edge = cut.voxel_size();
  const Vec3 start = cut.size * -0.5;
  int64_t x0, x1, y0, y1, z0, z1;
  VoxelRange(start.x, edge.x, cut.nx, lo.x, hi.x, &x0, &x1);
  VoxelRange(start.y, edge.y, cut.ny, lo.y, hi.y, &y0, &y1);
  VoxelRange(start.z, edge.z, cut.nz, lo.z, hi.z, &z0, &z1);
  for (int64_t z = z0; z <= z1; ++z)
    for (int64_t y = y0; y <= y1; ++y)
      for (int64_t x = x0; x <= x1; ++x) {
        const uint32_t i = static_cast<uint32_t>((z * cut.ny + y) * cut.nx + x);
        if (!block.Has(i)) continue;
        const Vec3 p_C{start.x + (x + 0.5) * edge.x, start.y + (y + 0.5) * edge.y,
                       start.z + (z + 0.5) * edge.z};
        if (Contains(volume, X_MC * p_C)) voxels->push_back(i);
      }
}

// The mill's finds, minus what earlier mills took this step.
void MillModule::Apply(Scene* scene, uint32_t mill_row) {
  auto& mills = static_cast<Rows<MillRow>&>(*scene->rows(mill_type_));
  auto& cuttables = static_cast<Rows<CuttableRow>&>(*scene->rows(cuttable_type_));
  MillRow& m = mills.rows[mill_row];
  for (const Found& f : found_[mill_row]) {
    CuttableRow& c = cuttables.rows[f.cuttable_row];
    Block& block = *blocks_[cuttables.owners[f.cuttable_row]];
    int64_t count = 0;
    for (uint32_t i : f.voxels) {
      if (!block.Has(i)) continue;
      block.Clear(i);
      c.digest += Mix(i);
      ++count;
    }
    c.remaining -= count;
    m.removed += static_cast<double>(count) * c.voxel_volume();
  }
}

void MillModule::CutMap(Scene* scene) {
  const EnvironmentMap* map = scene->environment();
  if (map == nullptr || map->boxes.empty()) return;
  auto& mills = static_cast<Rows<MillRow>&>(*scene->rows(mill_type_));
  const double voxel = map->resolution * map->resolution * map->resolution;
  for (const std::vector<uint32_t>& rows : mills_)
    for (uint32_t r : rows) {
      MillRow& m = mills.rows[r];
      if (!m.enabled) continue;
      const int64_t n = map_cutter_.Cut(*map, m.volume, scene->world_pose_at(mills.owners[r]));
      m.removed += static_cast<double>(n) * voxel;
      map_removed_voxels_ += n;
    }
  if (std::shared_ptr<const EnvironmentMap> next = map_cutter_.Finish(*map))
    scene->set_environment(std::move(next));
}

void MillModule::AfterPhysics(World* world) {
  Scene& scene = world->scene();
  if (version_ != scene.structure_version()) Refresh(&scene);
  if (!any_mills_) return;
  auto& mills = static_cast<Rows<MillRow>&>(*scene.rows(mill_type_));
  for (MillRow& m : mills.rows) m.removed = 0;
  EnsureBlocks(&scene);
  // 1. Robots' mills in parallel, then the scene's: finds only.
  const int64_t robots = static_cast<int64_t>(mills_.size()) - 1;
  world->scheduler().ParallelFor(0, robots, kMillGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r)
      for (uint32_t row : mills_[r]) Find(scene, row);
  });
  for (uint32_t row : mills_.back()) Find(scene, row);
  // 2. Applied in mill order; 3. the map, same order.
  for (const std::vector<uint32_t>& rows : mills_)
    for (uint32_t row : rows) Apply(&scene, row);
  CutMap(&scene);
  for (MillRow& m : mills.rows) m.removed_total += m.removed;
}

void MillModule::Record(const World& world, std::vector<MetricSample>* out) {
  if (!have_types_) return;
  const Scene& scene = world.scene();
  const auto sample = [&](uint32_t owner, const char* suffix, double value) {
    out->push_back({world.step_count(), world.time(), scene.instance_of_at(owner),
                    scene.name_at(owner) + suffix, value});
  };
  const auto& mills = static_cast<const Rows<MillRow>&>(*scene.rows(mill_type_));
  for (uint32_t r = 0; r < mills.size(); ++r)
    if (mills.rows[r].record) sample(mills.owners[r], ".removed", mills.rows[r].removed);
  const auto& cuttables = static_cast<const Rows<CuttableRow>&>(*scene.rows(cuttable_type_));
  for (uint32_t r = 0; r < cuttables.size(); ++r) {
    const CuttableRow& c = cuttables.rows[r];
    if (c.record)
      sample(cuttables.owners[r], ".remaining",
             static_cast<double>(c.remaining) * c.voxel_volume());
  }
}

void MillModule::ListOutputs(std::vector<OutputFile>* out) const {
  if (!have_types_) return;
  const Scene& scene = world_->scene();
  if (scene.rows(mill_type_)->size() == 0 && scene.rows(cuttable_type_)->size() == 0) return;
  out->push_back({"table", "mill.csv", "volume each mill removed and each cuttable has left"});
}

void MillModule::WriteOutputs(const std::filesystem::path& dir) const {
  if (!have_types_) return;
  const Scene& scene = world_->scene();
  const auto& mills = static_cast<const Rows<MillRow>&>(*scene.rows(mill_type_));
  const auto& cuttables = static_cast<const Rows<CuttableRow>&>(*scene.rows(cuttable_type_));
  if (mills.size() == 0 && cuttables.size() == 0) return;
  const std::filesystem::path path = dir / "mill.csv";
  std::ostringstream f;  // written whole at the end (WriteFileAtomically)
  f << "object,type,removed_m3,voxels,voxels_left,volume_left_m3\n";
  char line[160];
  for (uint32_t r = 0; r < mills.size(); ++r) {
    std::snprintf(line, sizeof line, ",mill,%.9g,,,\n", mills.rows[r].removed_total);
    f << scene.PathOf(scene.IdAt(mills.owners[r])) << line;
  }
  for (uint32_t r = 0; r < cuttables.size(); ++r) {
    const CuttableRow& c = cuttables.rows[r];
    const double v = c.voxel_volume();
    std::snprintf(line, sizeof line, ",cuttable,%.9g,%lld,%lld,%.9g\n",
                  static_cast<double>(c.voxel_count() - c.remaining) * v,
                  static_cast<long long>(c.voxel_count()), static_cast<long long>(c.remaining),
                  static_cast<double>(c.remaining) * v);
    f << scene.PathOf(scene.IdAt(cuttables.owners[r])) << line;
  }
  if (const EnvironmentMap* map = scene.environment()) {
    const double v = map->resolution * map->resolution * map->resolution;
    std::snprintf(line, sizeof line, "environment,map,%.9g,,,\n",
                  static_cast<double>(map_removed_voxels_) * v);
    f << line;
  }
  WriteFileAtomically(path, f.str());
}

void MillModule::HashState(StateHasher* hasher) const {
  if (map_removed_voxels_ == 0) return;  // worlds that never cut the map hash as before
  hasher->AddValue(map_removed_voxels_);
  const EnvironmentMap* map = world_->scene().environment();
  hasher->AddValue(static_cast<uint64_t>(map != nullptr ? map->boxes.size() : 0));
}

void MillModule::OnSubtreeRemoved(const Scene&, std::span<const uint32_t> slots) {
  for (uint32_t slot : slots)
    if (slot < blocks_.size()) blocks_[slot].reset();
}

}  // namespace swarmsim::mill
