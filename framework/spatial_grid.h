// A uniform 2D grid over (x, y) of circles, rebuilt every step: the broad
// phase for robot-vs-robot sensing, range-limited messaging and swarm metrics.
//
// Build() counting-sorts the items into cells by their centre (CSR arrays:
// cell_start + item indices; no per-cell vectors, and no allocation once the
// buffers have grown to the swarm's size). Items much larger than a cell
// (radius > cell_size / 2) and items with non-finite coordinates go to a
// short "oversize" list that every query scans, so one big box does not
// inflate the cost of every query. The grid spans the items' bounding box;
// the cell count is capped at kMaxCellsPerItem x items, so memory is O(N) even
// for far-apart clusters (at the price of coarser cells in that case).
//
// Queries return the items whose circle intersects (closed test) an AABB or a
// circle, in ascending item index, whatever the cell layout. Const queries
// are thread-safe. At constant density a query's cost does not grow with N.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace swarmsim {

struct GridItem {       // 32 bytes
  double x = 0, y = 0;  // centre, m
  double radius = 0;    // m, >= 0
  uint32_t id = 0;      // the caller's tag (e.g. a shape row); the grid does not read it
};

struct Aabb2 {  // 32 bytes
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
};

// The cells of a uniform grid (cell (0, 0)'s lower-left corner at origin,
// edge 1 / inv_cell, cells_x by cells_y) that `box` grown by `pad` can
// reach, with slack for rounding: columns ix0..ix1, rows iy0..iy1.
// false if none (also for a NaN box or an empty grid).
struct CellRange {
  int ix0 = 0, ix1 = -1, iy0 = 0, iy1 = -1;
};
bool CellsReached(const Aabb2& box, double pad, double origin_x, double origin_y, double inv_cell,
                  int cells_x, int cells_y, CellRange* out);

class SpatialGrid {
 public:
  static constexpr double kMaxCellsPerItem = 4;

  // Indexes `items` (copied). `cell_size` > 0 forces the cell edge (m);
  // otherwise it is chosen from the items' density and mean radius.
  void Build(std::span<const GridItem> items, double cell_size = 0);

  // Indices (into the span given to Build) of the items whose circle
  // intersects `box` / the circle (cx, cy, r), ascending. *out is cleared
  // first; it keeps its capacity, so a reused vector does not allocate.
  void QueryAabb(const Aabb2& box, std::vector<uint32_t>* out) const;
  void QueryCircle(double cx, double cy, double r, std::vector<uint32_t>* out) const;

  // Same, calling visit(index, item) in ascending index. Uses per-thread
  // scratch; `visit` may itself query the grid.
  template <class Visit>
  void ForEachInAabb(const Aabb2& box, Visit&& visit) const {
    ScratchLease lease;
    QueryAabb(box, lease.buffer);
    for (uint32_t i : *lease.buffer) visit(i, items_[i]);
  }
  template <class Visit>
  void ForEachInCircle(double cx, double cy, double r, Visit&& visit) const {
    ScratchLease lease;
    QueryCircle(cx, cy, r, lease.buffer);
    for (uint32_t i : *lease.buffer) visit(i, items_[i]);
  }

  // The intersection tests the queries use (closed: touching counts).
  static bool CircleIntersectsAabb(const GridItem& item, const Aabb2& box);
  static bool CircleIntersectsCircle(const GridItem& item, double cx, double cy, double r);

  std::span<const GridItem> items() const { return items_; }
  size_t size() const { return items_.size(); }
  bool empty() const { return items_.empty(); }
  double cell_size() const { return cell_size_; }
  int cells_x() const { return cells_x_; }
  int cells_y() const { return cells_y_; }
  size_t oversize_count() const { return oversize_.size(); }

 private:
  // A per-thread stack of scratch vectors, so nested ForEach calls on one
  // thread do not share a buffer.
  struct ScratchLease {
    ScratchLease();
    ~ScratchLease();
    ScratchLease(const ScratchLease&) = delete;
    ScratchLease& operator=(const ScratchLease&) = delete;
    std::vector<uint32_t>* buffer;
  };

  // Appends the items of the cells overlapping `box` grown by the largest
  // in-grid radius, and the oversize items, that pass `keep`; sorts.
  template <class Keep>
  void Collect(const Aabb2& box, Keep keep, std::vector<uint32_t>* out) const;

  std::vector<GridItem> items_;         // copy of the built items (items)
  std::vector<uint32_t> cell_start_;    // first entry of each cell in cell_items_ (cells + 1)
  std::vector<uint32_t> cell_items_;    // item indices, grouped by cell, ascending within a cell
  std::vector<GridItem> cell_data_;     // items_[cell_items_[e]], stored in cell order for locality
  std::vector<uint32_t> oversize_;      // items scanned by every query, ascending
  std::vector<uint32_t> cell_of_item_;  // build scratch: cell per item, or kNoCell (items)
  double origin_x_ = 0, origin_y_ = 0;  // lower-left corner of cell (0, 0), m
  double cell_size_ = 1;                // m
  double inv_cell_size_ = 1;            // 1/m
  double max_radius_ = 0;               // largest radius among in-grid items, m
  int cells_x_ = 0, cells_y_ = 0;
};

}  // namespace swarmsim
