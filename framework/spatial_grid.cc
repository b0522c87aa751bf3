#include "framework/spatial_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace swarmsim {
namespace {

constexpr uint32_t kNoCell = std::numeric_limits<uint32_t>::max();

bool IsFinite(const GridItem& item) {
  return std::isfinite(item.x) && std::isfinite(item.y) && std::isfinite(item.radius);
}

// Per-thread stack of query buffers (see ScratchLease).
struct ScratchStack {
  std::vector<std::unique_ptr<std::vector<uint32_t>>> buffers;
  size_t depth = 0;
};
thread_local ScratchStack t_scratch;

// Is (dx, dy) within `reach` of the origin? The early box test rejects most
// misses cheaply and NaNs; hypot keeps huge reaches from overflowing.
bool Within(double dx, double dy, double reach) {
  if (!(std::abs(dx) <= reach && std::abs(dy) <= reach)) return false;
  if (reach > 1e150) return std::hypot(dx, dy) <= reach;
  return dx * dx + dy * dy <= reach * reach;
}

}  // namespace

SpatialGrid::ScratchLease::ScratchLease() {
  if (t_scratch.depth == t_scratch.buffers.size())
    t_scratch.buffers.push_back(std::make_unique<std::vector<uint32_t>>());
  buffer = t_scratch.buffers[t_scratch.depth++].get();
}

SpatialGrid::ScratchLease::~ScratchLease() { --t_scratch.depth; }

bool SpatialGrid::CircleIntersectsAabb(const GridItem& item, const Aabb2& box) {
  const double dx = std::max(std::max(box.min_x - item.x, item.x - box.max_x), 0.0);
  const double dy = std::max(std::max(box.min_y - item.y, item.y - box.max_y), 0.0);
  return Within(dx, dy, item.radius);
}

bool SpatialGrid::CircleIntersectsCircle(const GridItem& item, double cx, double cy, double r) {
  return Within(item.x - cx, item.y - cy, item.radius + r);
}

void SpatialGrid::Build(std::span<const GridItem> items, double cell_size) {
  // Copy, clamping negative radii to zero.
  items_.assign(items.begin(), items.end());
  for (GridItem& item : items_)
    if (item.radius < 0) item.radius = 0;
  oversize_.clear();
  cells_x_ = cells_y_ = 0;
  max_radius_ = 0;
  const size_t n = items_.size();
  cell_of_item_.resize(n);

  // Bounding box and mean radius of the finite items.
  double min_x = std::numeric_limits<double>::infinity(), min_y = min_x;
  double max_x = -min_x, max_y = -min_x, radius_sum = 0;
  size_t finite = 0;
  for (const GridItem& item : items_) {
    if (!IsFinite(item)) continue;
    min_x = std::min(min_x, item.x), max_x = std::max(max_x, item.x);
    min_y = std::min(min_y, item.y), max_y = std::max(max_y, item.y);
    radius_sum += item.radius;
    ++finite;
  }
  const double width = max_x - min_x, height = max_y - min_y;
  bool gridded = finite > 0 && std::isfinite(width) && std::isfinite(height);

  if (gridded) {
    // Cell edge: forced, else about one item per cell and at least four mean radii.
    double cell = cell_size;
    if (!(cell > 0) || !std::isfinite(cell)) {
      const double spacing = width > 0 && height > 0       ? std::sqrt(width * height / finite)
                             : std::max(width, height) > 0 ? std::max(width, height) / finite
                                                           : 1.0;
      cell = std::max(spacing, 4 * radius_sum / finite);
      if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    }
    // Cap the cell count so memory stays O(N).
    const double max_cells = std::max(kMaxCellsPerItem * finite, 1.0);
    double nx = std::floor(width / cell) + 1, ny = std::floor(height / cell) + 1;
    while (nx * ny > max_cells) {
      cell *= std::max(std::sqrt(nx * ny / max_cells), 1.0 + 1e-9);
      nx = std::floor(width / cell) + 1, ny = std::floor(height / cell) + 1;
    }
    // (A spread near the double range can overflow the cell edge: then every
    // item goes to the oversize list, correct but linear.)
    gridded = std::isfinite(cell) && cell > 0;
    if (gridded) {
      cell_size_ = cell;
      inv_cell_size_ = 1 / cell;
      origin_x_ = min_x, origin_y_ = min_y;
      cells_x_ = static_cast<int>(nx), cells_y_ = static_cast<int>(ny);
    }
  }

  // Assign each item a cell (or the oversize list) and count per cell.
  const size_t cell_count = static_cast<size_t>(cells_x_) * static_cast<size_t>(cells_y_);
  cell_start_.assign(cell_count + 1, 0);
  const double oversize_radius = cell_size_ / 2;
  for (size_t i = 0; i < n; ++i) {
    const GridItem& item = items_[i];
    if (!gridded || !IsFinite(item) || item.radius > oversize_radius) {
      cell_of_item_[i] = kNoCell;
      oversize_.push_back(static_cast<uint32_t>(i));
      continue;
    }
    const int ix = std::min(static_cast<int>((item.x - origin_x_) * inv_cell_size_), cells_x_ - 1);
    const int iy = std::min(static_cast<int>((item.y - origin_y_) * inv_cell_size_), cells_y_ - 1);
    const uint32_t c = static_cast<uint32_t>(iy) * static_cast<uint32_t>(cells_x_) + ix;
    cell_of_item_[i] = c;
    ++cell_start_[c];
    max_radius_ = std::max(max_radius_, item.radius);
  }

  // Counting sort: running ends, then place items back to front so each
  // cell lists its items in ascending index.
  uint32_t running = 0;
  for (size_t c = 0; c < cell_count; ++c) running = (cell_start_[c] += running);
  cell_start_[cell_count] = running;
  cell_items_.resize(running);
  cell_data_.resize(running);
  for (size_t i = n; i-- > 0;) {
    if (cell_of_item_[i] == kNoCell) continue;
    const uint32_t e = --cell_start_[cell_of_item_[i]];
    cell_items_[e] = static_cast<uint32_t>(i);
    cell_data_[e] = items_[i];
  }
}

bool CellsReached(const Aabb2& box, double pad, double origin_x, double origin_y, double inv_cell,
                  int cells_x, int cells_y, CellRange* out) {
  if (cells_x <= 0 || cells_y <= 0) return false;
  const double slack_x = 1e-12 * (std::abs(box.min_x) + std::abs(box.max_x) + std::abs(origin_x));
  const double slack_y = 1e-12 * (std::abs(box.min_y) + std::abs(box.max_y) + std::abs(origin_y));
  const double grow = pad * (1 + 1e-12) + 1e-300;
  const double lo_x = std::floor((box.min_x - grow - slack_x - origin_x) * inv_cell);
  const double hi_x = std::floor((box.max_x + grow + slack_x - origin_x) * inv_cell);
  const double lo_y = std::floor((box.min_y - grow - slack_y - origin_y) * inv_cell);
  const double hi_y = std::floor((box.max_y + grow + slack_y - origin_y) * inv_cell);
  // (Negated comparisons so NaN boxes fall through to "nothing".)
  if (!(lo_x <= hi_x && lo_y <= hi_y && hi_x >= 0 && hi_y >= 0 && lo_x < cells_x && lo_y < cells_y))
    return false;
  out->ix0 = static_cast<int>(std::max(lo_x, 0.0));
  out->ix1 = static_cast<int>(std::min(hi_x, cells_x - 1.0));
  out->iy0 = static_cast<int>(std::max(lo_y, 0.0));
  out->iy1 = static_cast<int>(std::min(hi_y, cells_y - 1.0));
  return true;
}

template <class Keep>
void SpatialGrid::Collect(const Aabb2& box, Keep keep, std::vector<uint32_t>* out) const {
  out->clear();
  CellRange c;
  if (CellsReached(box, max_radius_, origin_x_, origin_y_, inv_cell_size_, cells_x_, cells_y_,
                   &c)) {
    // Cells of a row are contiguous in cell_items_.
    for (int iy = c.iy0; iy <= c.iy1; ++iy) {
      const size_t row = static_cast<size_t>(iy) * cells_x_;
      for (uint32_t e = cell_start_[row + c.ix0]; e < cell_start_[row + c.ix1 + 1]; ++e)
        if (keep(cell_data_[e])) out->push_back(cell_items_[e]);
    }
  }
  for (uint32_t i : oversize_)
    if (keep(items_[i])) out->push_back(i);
  // Items from several cells interleave; restore ascending index order
  // (std::sort does not allocate, unlike std::inplace_merge).
  std::sort(out->begin(), out->end());
}

void SpatialGrid::QueryAabb(const Aabb2& box, std::vector<uint32_t>* out) const {
  Collect(
      box, [&box](const GridItem& item) { return CircleIntersectsAabb(item, box); }, out);
}

void SpatialGrid::QueryCircle(double cx, double cy, double r, std::vector<uint32_t>* out) const {
  if (!(r >= 0)) {  // a negative or NaN radius reaches nothing
    out->clear();
    return;
  }
  const Aabb2 box{cx - r, cy - r, cx + r, cy + r};
  Collect(
      box, [=](const GridItem& item) { return CircleIntersectsCircle(item, cx, cy, r); }, out);
}

}  // namespace swarmsim
