#include "modules/environment/voxel_merge.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <tuple>

#include "framework/error.h"

namespace swarmsim::environment {
namespace {

// The band's voxels on the map's grid: layer k (0 = the band's lowest)
// spans [z0 + k res, z0 + (k + 1) res].
struct BandGrid {
  double x0 = 0, y0 = 0, z0 = 0;
  double res = 0;   // m, one layer (the map's voxel)
  double cell = 0;  // m, a cell's side in x and y (a power-of-two number of voxels)
  int nx = 0, ny = 0, nz = 0;
  std::vector<uint8_t> cells;  // (nz x ny x nx)
};

// Index on the map's voxel grid of a coordinate that lies on it.
int GridIndex(const EnvironmentMap& map, double value, double origin) {
  const double f = (value - origin) / map.resolution;
  const double r = std::round(f);
  if (!(std::abs(f - r) <= 1e-6))
    throw Error("environment " + map.source + ": a box does not lie on the map's voxel grid");
  return static_cast<int>(r);
}

// The largest power of two (at most 2^20) that divides every box's x and y
// cell indices and the map's extent: the cell of the band's grid, in voxels.
// A pruned leaf is a cube of 2^k voxels on its own grid, so a map made of a
// few big leaves gets a few big cells instead of millions of small ones; the
// boxes merged from either grid are the same.
int CoarseFactor(const EnvironmentMap& map) {
  constexpr int kMax = 1 << 20;
  int bits = kMax;  // every index's bits: the lowest set one is the factor
  auto take = [&](double value, double origin) { bits |= GridIndex(map, value, origin); };
  take(map.hi.x, map.lo.x);
  take(map.hi.y, map.lo.y);
  for (const EnvironmentBox& b : map.boxes) {
    if (bits & 1) break;
    take(b.lo.x, map.lo.x), take(b.hi.x, map.lo.x);
    take(b.lo.y, map.lo.y), take(b.hi.y, map.lo.y);
  }
  return bits & -bits;
}

// The grid of the voxels in the band (z_lo, z_hi); `project`: one layer,
// the columns' union. Its cells are CoarseFactor voxels wide in x and y,
// one voxel high.
BandGrid MakeGrid(const EnvironmentMap& map, double z_lo, double z_hi, bool project) {
  BandGrid g;
  if (map.boxes.empty() || !(map.resolution > 0) || !(z_lo < z_hi)) return g;
  const int f = CoarseFactor(map);
  g.res = map.resolution;
  g.cell = map.resolution * f;
  const int layers = GridIndex(map, map.hi.z, map.lo.z);
  auto bottom = [&](int k) { return map.lo.z + k * g.res; };
  // Layers [k_lo, k_hi): top > z_lo and bottom < z_hi.
  int k_lo = 0, k_hi = layers;
  while (k_lo < layers && !(bottom(k_lo + 1) > z_lo)) ++k_lo;
  while (k_hi > k_lo && !(bottom(k_hi - 1) < z_hi)) --k_hi;
  if (k_lo >= k_hi) return g;
  g.x0 = map.lo.x, g.y0 = map.lo.y, g.z0 = bottom(k_lo);
  g.nx = GridIndex(map, map.hi.x, map.lo.x) / f;
  g.ny = GridIndex(map, map.hi.y, map.lo.y) / f;
  g.nz = project ? 1 : k_hi - k_lo;
  // One byte a cell, at most kMaxGridCells and at most the map's max_memory_mb.
  const int64_t cells = int64_t{g.nx} * g.ny * g.nz;
  const double limit = std::min(static_cast<double>(kMaxGridCells), map.max_grid_bytes);
  if (static_cast<double>(cells) > limit) {
    std::ostringstream m;
    m << "environment " << map.source << ": the map's band from z " << z_lo << " to " << z_hi
      << " m needs a grid of " << cells << " cells (" << g.nx << " x " << g.ny << " x " << g.nz
      << ", " << g.cell << " m), one byte each, more than "
      << (map.max_grid_bytes < kMaxGridCells ? "its max_memory_mb allows"
                                             : "the limit of " + std::to_string(kMaxGridCells))
      << " (crop the map with z_range or a bounding box, use a coarser map, or raise "
         "max_memory_mb)";
    throw Error(m.str());
  }
  g.cells.assign(size_t(g.nx) * size_t(g.ny) * size_t(g.nz), 0);
  for (const EnvironmentBox& b : map.boxes) {
    const int k0 = std::max(GridIndex(map, b.lo.z, map.lo.z), k_lo);
    const int k1 = std::min(GridIndex(map, b.hi.z, map.lo.z), k_hi);
    if (k0 >= k1) continue;
    const int i0 = GridIndex(map, b.lo.x, map.lo.x) / f, i1 = GridIndex(map, b.hi.x, map.lo.x) / f;
    const int j0 = GridIndex(map, b.lo.y, map.lo.y) / f, j1 = GridIndex(map, b.hi.y, map.lo.y) / f;
    for (int k = project ? 0 : k0 - k_lo; k < (project ? 1 : k1 - k_lo); ++k)
      for (int j = j0; j < j1; ++j)
        std::fill_n(&g.cells[(size_t(k) * g.ny + j) * g.nx + i0], i1 - i0, uint8_t{1});
  }
  if (project) g.nz = k_hi - k_lo;  // the boxes' height: every layer of the band
  return g;
}

struct Rect {  // half-open cell ranges
  int x0, x1, y0, y1;
  auto Key() const { return std::tie(x0, x1, y0, y1); }
};

// One layer's occupied cells as rectangles: runs along x, merged along y.
std::vector<Rect> MergeLayer(const uint8_t* layer, int nx, int ny) {
  std::vector<Rect> done, open, next;
  std::vector<std::array<int, 2>> runs;
  for (int y = 0; y <= ny; ++y) {
    runs.clear();
    if (y < ny) {
      const uint8_t* row = layer + size_t(y) * nx;
      for (int x = 0; x < nx;) {
        if (!row[x]) {
          ++x;
          continue;
        }
        const int start = x;
        while (x < nx && row[x]) ++x;
        runs.push_back({start, x});
      }
    }
    // Open rectangles (sorted by x0, disjoint) continue where a run has their extent.
    next.clear();
    size_t a = 0, b = 0;
    while (a < open.size() || b < runs.size()) {
      if (b == runs.size() || (a < open.size() && open[a].x0 < runs[b][0])) {
        open[a].y1 = y;
        done.push_back(open[a++]);
      } else if (a == open.size() || runs[b][0] < open[a].x0) {
        next.push_back({runs[b][0], runs[b][1], y, 0});
        ++b;
      } else {
        if (open[a].x1 == runs[b][1]) {
          next.push_back(open[a]);
        } else {
          open[a].y1 = y;
          done.push_back(open[a]);
          next.push_back({runs[b][0], runs[b][1], y, 0});
        }
        ++a, ++b;
      }
    }
    open.swap(next);
  }
  return done;
}

struct CellBox {  // half-open cell ranges
  Rect r;
  int z0, z1;
};

std::vector<EnvironmentBox> ToBoxes(std::vector<CellBox> boxes, const BandGrid& g) {
  std::sort(boxes.begin(), boxes.end(), [](const CellBox& a, const CellBox& b) {
    return std::tie(a.z0, a.r.y0, a.r.x0) < std::tie(b.z0, b.r.y0, b.r.x0);
  });
  std::vector<EnvironmentBox> out;
  out.reserve(boxes.size());
  for (const CellBox& c : boxes)
    out.push_back({{g.x0 + c.r.x0 * g.cell, g.y0 + c.r.y0 * g.cell, g.z0 + c.z0 * g.res},
                   {g.x0 + c.r.x1 * g.cell, g.y0 + c.r.y1 * g.cell, g.z0 + c.z1 * g.res}});
  return out;
}

}  // namespace

std::vector<EnvironmentBox> MergeBand3D(const EnvironmentMap& map, double z_lo, double z_hi) {
  const BandGrid g = MakeGrid(map, z_lo, z_hi, /*project=*/false);
  std::vector<CellBox> done, open, next;
  for (int z = 0; z <= g.nz; ++z) {
    std::vector<Rect> rects;
    if (z < g.nz) rects = MergeLayer(&g.cells[size_t(z) * g.nx * g.ny], g.nx, g.ny);
    std::sort(rects.begin(), rects.end(),
              [](const Rect& a, const Rect& b) { return a.Key() < b.Key(); });
    // Open boxes (sorted by their rectangle) go on where this layer has the same rectangle.
    next.clear();
    size_t a = 0, b = 0;
    while (a < open.size() || b < rects.size()) {
      if (b == rects.size() || (a < open.size() && open[a].r.Key() < rects[b].Key())) {
        open[a].z1 = z;
        done.push_back(open[a++]);
      } else if (a == open.size() || rects[b].Key() < open[a].r.Key()) {
        next.push_back({rects[b++], z, 0});
      } else {
        next.push_back(open[a]);
        ++a, ++b;
      }
    }
    open.swap(next);
  }
  return ToBoxes(std::move(done), g);
}

std::vector<EnvironmentBox> MergeBand2D(const EnvironmentMap& map, double z_lo, double z_hi) {
  const BandGrid g = MakeGrid(map, z_lo, z_hi, /*project=*/true);
  if (g.cells.empty()) return {};
  std::vector<CellBox> boxes;
  for (const Rect& r : MergeLayer(g.cells.data(), g.nx, g.ny)) boxes.push_back({r, 0, g.nz});
  return ToBoxes(std::move(boxes), g);
}

PlaneGrid ProjectBand(const EnvironmentMap& map, double z_lo, double z_hi) {
  BandGrid g = MakeGrid(map, z_lo, z_hi, /*project=*/true);
  PlaneGrid out;
  if (g.cells.empty()) return out;
  out.x0 = g.x0, out.y0 = g.y0, out.cell = g.cell;
  out.nx = g.nx, out.ny = g.ny;
  out.occupied = std::move(g.cells);
  return out;
}

}  // namespace swarmsim::environment
