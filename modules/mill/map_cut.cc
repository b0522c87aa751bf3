#include "modules/mill/map_cut.h"

#include <algorithm>
#include <cmath>

#include "modules/mill/rows.h"

namespace swarmsim::mill {

namespace {

bool Overlap(const Vec3& a_lo, const Vec3& a_hi, const Vec3& b_lo, const Vec3& b_hi) {
  return a_lo.x <= b_hi.x && b_lo.x <= a_hi.x && a_lo.y <= b_hi.y && b_lo.y <= a_hi.y &&
         a_lo.z <= b_hi.z && b_lo.z <= a_hi.z;
}

// (Clamped before the cast: a far or NaN coordinate is no undefined behaviour.)
int64_t CellOf(double coordinate, double cell) {
  const double c = std::floor(coordinate / cell);
  return c >= -4e18 ? static_cast<int64_t>(std::min(c, 4e18)) : int64_t{-4'000'000'000'000'000'000};
}

// What CutBox's recursion shares.
struct CutContext {
  double resolution;
  const Volume& volume;
  const Pose& X_MW;
  Vec3 bounds_lo, bounds_hi;  // the volume's bounds, mill frame
  std::vector<EnvironmentBox>* out;
};

// The part [lo, hi] of a box, n[i] voxels along axis i.
int64_t CutPart(const CutContext& c, const Vec3& lo, const Vec3& hi, const int64_t n[3]) {
  const Vec3 edge{(hi.x - lo.x) / n[0], (hi.y - lo.y) / n[1], (hi.z - lo.z) / n[2]};
  // The hull of the part's voxel centres, in the mill's frame.
  const Vec3 c_lo = lo + edge * 0.5, c_hi = hi - edge * 0.5;
  Vec3 m_lo{INFINITY, INFINITY, INFINITY}, m_hi{-INFINITY, -INFINITY, -INFINITY};
  bool all_inside = true;
  for (int k = 0; k < 8; ++k) {
    const Vec3 p =
        c.X_MW * Vec3{k & 1 ? c_hi.x : c_lo.x, k & 2 ? c_hi.y : c_lo.y, k & 4 ? c_hi.z : c_lo.z};
    m_lo = {std::min(m_lo.x, p.x), std::min(m_lo.y, p.y), std::min(m_lo.z, p.z)};
    m_hi = {std::max(m_hi.x, p.x), std::max(m_hi.y, p.y), std::max(m_hi.z, p.z)};
    all_inside = all_inside && Contains(c.volume, p);
  }
  // Every centre inside (the volume is convex): the whole part goes.
  if (all_inside) return n[0] * n[1] * n[2];
  const EnvironmentBox whole{lo, hi};
  if (!Overlap(m_lo, m_hi, c.bounds_lo, c.bounds_hi) || (n[0] == 1 && n[1] == 1 && n[2] == 1)) {
    c.out->push_back(whole);
    return 0;
  }
  // Halve each axis with more than one voxel; children in octree order (x fastest).
  const size_t start = c.out->size();
  int64_t removed = 0;
  const int64_t half[3] = {n[0] / 2, n[1] / 2, n[2] / 2};
  const double split[3] = {lo.x + edge.x * half[0], lo.y + edge.y * half[1],
                           lo.z + edge.z * half[2]};
  for (int k = 0; k < 8; ++k) {
    const bool upper[3] = {(k & 1) != 0, (k & 2) != 0, (k & 4) != 0};
    Vec3 child_lo = lo, child_hi = hi;
    int64_t child_n[3];
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      double* l = a == 0 ? &child_lo.x : a == 1 ? &child_lo.y : &child_lo.z;
      double* h = a == 0 ? &child_hi.x : a == 1 ? &child_hi.y : &child_hi.z;
      if (n[a] == 1) {  // not split along a: the lower child takes it whole
        empty = empty || upper[a];
        child_n[a] = 1;
      } else if (upper[a]) {
        *l = split[a];
        child_n[a] = n[a] - half[a];
      } else {
        *h = split[a];
        child_n[a] = half[a];
      }
    }
    if (!empty) removed += CutPart(c, child_lo, child_hi, child_n);
  }
  if (removed == 0) {  // nothing went: keep the part whole, unsplit
    c.out->resize(start);
    c.out->push_back(whole);
  }
  return removed;
}

}  // namespace

uint64_t MapIndex::Bucket(int64_t x, int64_t y, int64_t z) {
  return Mix(static_cast<uint64_t>(x) ^
             Mix(static_cast<uint64_t>(y) ^ Mix(static_cast<uint64_t>(z))));
}

void MapIndex::Build(const EnvironmentMap& map) {
  map_ = &map;
  data_ = map.boxes.data();
  size_ = map.boxes.size();
  levels_.clear();
  const double resolution = map.resolution > 0 ? map.resolution : 1;
  // The levels, and each box's.
  std::map<int, size_t> level_of;  // k -> levels_ index
  for (uint32_t b = 0; b < map.boxes.size(); ++b) {
    const EnvironmentBox& box = map.boxes[b];
    const double edge = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
    const int k = std::clamp(static_cast<int>(std::lround(std::log2(edge / resolution))), 0, 60);
    auto [it, added] = level_of.try_emplace(k, levels_.size());
    if (added) {
      levels_.emplace_back();
      levels_.back().cell = std::ldexp(resolution, k);
    }
    Level& level = levels_[it->second];
    level.max_edge = std::max(level.max_edge, edge);
    level.boxes.push_back(b);
  }
  // Each level's buckets: count, prefix sums, fill (boxes stay ascending).
  std::vector<uint64_t> bucket_of;
  for (Level& level : levels_) {
    uint64_t buckets = 1;
    while (buckets < level.boxes.size()) buckets <<= 1;
    level.mask = buckets - 1;
    level.start.assign(buckets + 1, 0);
    bucket_of.resize(level.boxes.size());
    for (size_t i = 0; i < level.boxes.size(); ++i) {
      const EnvironmentBox& box = map.boxes[level.boxes[i]];
      bucket_of[i] = Bucket(CellOf(box.lo.x, level.cell), CellOf(box.lo.y, level.cell),
                            CellOf(box.lo.z, level.cell)) &
                     level.mask;
      ++level.start[bucket_of[i] + 1];
    }
    for (uint64_t b = 0; b < buckets; ++b) level.start[b + 1] += level.start[b];
    level.entries.resize(level.boxes.size());
    std::vector<uint32_t> next(level.start.begin(), level.start.end() - 1);
    for (size_t i = 0; i < level.boxes.size(); ++i)
      level.entries[next[bucket_of[i]]++] = level.boxes[i];
  }
}

void MapIndex::Query(const Vec3& lo, const Vec3& hi, std::vector<uint32_t>* out) const {
  out->clear();
  const auto keep = [&](uint32_t b) {
    const EnvironmentBox& box = data_[b];
    if (Overlap(box.lo, box.hi, lo, hi)) out->push_back(b);
  };
  for (const Level& level : levels_) {
    // A box overlapping [lo, hi] has its low corner in [lo - max_edge, hi].
    const double e = level.max_edge;
    const int64_t x0 = CellOf(lo.x - e, level.cell), x1 = CellOf(hi.x, level.cell);
    const int64_t y0 = CellOf(lo.y - e, level.cell), y1 = CellOf(hi.y, level.cell);
    const int64_t z0 = CellOf(lo.z - e, level.cell), z1 = CellOf(hi.z, level.cell);
    const double cells = static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1) *
                         static_cast<double>(z1 - z0 + 1);
    if (cells >= static_cast<double>(level.boxes.size())) {  // fewer boxes than cells: scan
      for (uint32_t b : level.boxes) keep(b);
      continue;
    }
    for (int64_t z = z0; z <= z1; ++z)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) {
          const uint64_t bucket = Bucket(x, y, z) & level.mask;
          for (uint32_t i = level.start[bucket]; i < level.start[bucket + 1]; ++i)
            keep(level.entries[i]);
        }
  }
  // Two cells may share a bucket: a box may have been kept twice.
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

int64_t CutBox(const EnvironmentBox& box, double resolution, const Volume& volume, const Pose& X_MW,
               std::vector<EnvironmentBox>* out) {
  CutContext c{resolution, volume, X_MW, {}, {}, out};
  Bounds(volume, &c.bounds_lo, &c.bounds_hi);
  // Voxels per axis; past 2^20 a side (10 km at 0.01 m: no octree has them)
  // the voxels grow instead, so counts stay within 64 bits.
  const auto voxels = [&](double side) {
    const double n = std::round(side / resolution);
    return n >= 1 ? static_cast<int64_t>(std::min(n, 1048576.0)) : int64_t{1};
  };
  const int64_t n[3] = {voxels(box.hi.x - box.lo.x), voxels(box.hi.y - box.lo.y),
                        voxels(box.hi.z - box.lo.z)};
  return CutPart(c, box.lo, box.hi, n);
}

int64_t MapCutter::Cut(const EnvironmentMap& map, const Volume& volume, const Pose& X_WM) {
  if (map.boxes.empty() || !(map.resolution > 0)) return 0;
  Vec3 lo, hi;
  WorldBounds(volume, X_WM, &lo, &hi);
  if (!Overlap(lo, hi, map.lo, map.hi)) return 0;
  if (!index_.Follows(map)) index_.Build(map);
  index_.Query(lo, hi, &hits_);
  const Pose X_MW = X_WM.Inverse();
  int64_t removed = 0;
  std::vector<EnvironmentBox> left;
  for (uint32_t b : hits_) {
    const auto it = replaced_.find(b);
    left.clear();
    int64_t here = 0;
    if (it == replaced_.end()) {
      here = CutBox(map.boxes[b], map.resolution, volume, X_MW, &left);
    } else {
      for (const EnvironmentBox& piece : it->second)
        here += CutBox(piece, map.resolution, volume, X_MW, &left);
    }
    if (here == 0) continue;
    removed += here;
    replaced_[b] = left;
  }
  return removed;
}

std::shared_ptr<const EnvironmentMap> MapCutter::Finish(const EnvironmentMap& map) {
  if (replaced_.empty()) return nullptr;
  auto next = std::make_shared<EnvironmentMap>();
  next->source = map.source;
  next->resolution = map.resolution;
  next->boxes.reserve(map.boxes.size() + replaced_.size() * 8);
  auto it = replaced_.begin();
  for (uint32_t b = 0; b < map.boxes.size(); ++b) {
    if (it != replaced_.end() && it->first == b) {
      next->boxes.insert(next->boxes.end(), it->second.begin(), it->second.end());
      ++it;
    } else {
      next->boxes.push_back(map.boxes[b]);
    }
  }
  replaced_.clear();
  if (!next->boxes.empty()) {
    next->lo = next->boxes[0].lo;
    next->hi = next->boxes[0].hi;
    for (const EnvironmentBox& box : next->boxes) {
      next->lo = {std::min(next->lo.x, box.lo.x), std::min(next->lo.y, box.lo.y),
                  std::min(next->lo.z, box.lo.z)};
      next->hi = {std::max(next->hi.x, box.hi.x), std::max(next->hi.y, box.hi.y),
                  std::max(next->hi.z, box.hi.z)};
    }
  }
  held_ = next;
  return next;
}

}  // namespace swarmsim::mill
