// The robot broad phase of the proximity early-out: a uniform 2D grid over
// the world xy plane of the footprints of robot and dynamic shapes, rebuilt
// every step, that answers "does a shape of another robot come near this
// box?" with no allocation, no sort and an early exit.
//
// Footprints are squares (the caller's bounding squares of the shapes'
// footprint circles, grown for rounding): testing squares, not circles,
// finds a superset, which is all the early-out needs (every shape a ray
// could hit is found; the rays do the exact tests). The grid holds one entry
// per robot, the union of its shapes' squares, and one per shape of no
// robot: a query meets few entries and skips its own robot's at once.
// Entries much larger than a cell, or not finite, go to a short list every
// query scans. Cell count is capped at a few per entry, so memory is
// O(shapes) however far apart they are.
//
// Internal to modules/proximity.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "framework/handle.h"
#include "framework/spatial_grid.h"

namespace swarmsim {
class TaskScheduler;
}

namespace swarmsim::proximity {

class FootprintGrid {
 public:
  // Indexes shapes i = 0..n-1: square[i] (finite or not), the robot
  // instance[i] it belongs to (or -1) and its id[i] (copied). With a
  // scheduler, arrays that must grow have their pages populated on its
  // threads first (a large swarm's first build: fresh memory).
  void Build(std::span<const Aabb2> squares, std::span<const int32_t> instances,
             std::span<const ObjectId> ids, TaskScheduler* scheduler = nullptr);

  // Is there a shape whose square meets `box` (closed) and that is neither
  // of robot `instance` (if >= 0) nor listed in `skip`?
  bool AnyOther(const Aabb2& box, int instance, std::span<const ObjectId> skip) const;

  // The indices of those shapes, ascending (*out cleared first).
  void Others(const Aabb2& box, int instance, std::span<const ObjectId> skip,
              std::vector<uint32_t>* out) const;

 private:
  struct Entry {       // 40 bytes
    Aabb2 square;      // union of its shapes' squares
    int32_t instance;  // its robot, or -1
    uint32_t group;    // its shapes: group_start_[group] .. group_start_[group + 1]
  };

  // Calls visit(entry) for the entries of the cells `box` may reach and the
  // oversize entries, until it returns true; returns whether one did.
  template <class Visit>
  bool Scan(const Aabb2& box, Visit&& visit) const;

  // Groups (robots, or shapes of no robot) and their shapes.
  std::vector<Aabb2> group_squares_;        // (groups)
  std::vector<int32_t> group_instance_;     // (groups)
  std::vector<uint32_t> group_start_;       // first of each group's shapes in members_ (groups + 1)
  std::vector<uint32_t> members_;           // shape indices, ascending per group
  std::vector<Aabb2> squares_;              // copy of the shapes' squares (shapes)
  std::vector<ObjectId> ids_;               // copy of their ids (shapes)
  std::vector<int32_t> group_of_instance_;  // build scratch (instances)
  std::vector<uint32_t> group_of_shape_;    // build scratch (shapes)

  // The grid of group entries.
  std::vector<Entry> cell_entries_;      // grouped by cell
  std::vector<uint32_t> cell_start_;     // first entry of each cell (cells + 1)
  std::vector<Entry> oversize_;          // entries every query scans
  std::vector<uint32_t> cell_of_group_;  // build scratch (groups)
  double origin_x_ = 0, origin_y_ = 0;   // lower-left corner of cell (0, 0), m
  double inv_cell_size_ = 1;             // 1/m
  double max_half_ = 0;                  // largest half edge of an in-grid entry, m
  int cells_x_ = 0, cells_y_ = 0;
};

}  // namespace swarmsim::proximity
