// Placing model copies in the plane without overlap (a world's
// `distribute:`): random sequential placement with a bounded number of
// attempts per copy, overlap checks through a uniform hash grid so that
// 10,000 copies place in milliseconds.
//
// Everything is a footprint in the (x, y) plane: a copy is a disc around its
// root; an obstacle or wall is a disc or an oriented rectangle. Placement is
// deterministic: the same seed, stream and calls give the same poses.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "framework/environment.h"
#include "framework/random.h"

namespace swarmsim {

// Random streams of placement, far from the robots' streams (0, 1, 2, ...)
// and the scene's (2^63): distribute entry k uses kPlacementStream + k.
inline constexpr uint64_t kPlacementStream = 0x706c6163656d6e74;  // "placemnt"

// A static footprint in the plane.
struct Obstacle2 {
  enum class Kind : uint8_t { kCircle, kBox };
  Kind kind = Kind::kCircle;
  double x = 0, y = 0;            // centre, m
  double radius = 0;              // kCircle, m
  double half_x = 0, half_y = 0;  // kBox: half extents along its own axes, m
  double yaw = 0;                 // kBox: rotation about z, rad
  // Heights it spans, m: one wholly above or below the copies is none of
  // theirs (Placer::KeepObstaclesReaching).
  double lo = -INFINITY, hi = INFINITY;

  // Signed distance from (px, py) to the footprint's edge (negative inside), m.
  double Distance(double px, double py) const;
  // Radius of a circle around (x, y) holding the footprint, m.
  double BoundingRadius() const;
};

struct Region2 {  // an axis-aligned rectangle, m
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
};

struct Placement2 {     // a copy's root in the plane
  double x = 0, y = 0;  // m
  double yaw = 0;       // rad
};

// Renumbers `placements` along a Hilbert curve over their bounding box, in
// square cells of `cell` m (about one copy each): copies that stand near
// each other get near numbers. Every phase of a step walks robots in the
// order of their numbers and keeps each robot's rows, body and script in
// that order in memory, so neighbours (whose shapes a robot's sensors meet,
// whose bodies touch its own) are then near in memory too. Deterministic:
// copies in one cell keep their order.
void SortAlongCurve(std::vector<Placement2>* placements, double cell);

class Placer {
 public:
  // Tries per copy before the region counts as full.
  static constexpr int kMaxAttempts = 2000;

  explicit Placer(uint64_t seed) : seed_(seed) {}
  // The same walls, obstacles, map and bodies, drawing from another seed
  // (World.reset(seed): the placement a load with that seed makes).
  Placer WithSeed(uint64_t seed) const {
    Placer copy = *this;
    copy.seed_ = seed;
    return copy;
  }

  // Called every 4,096 copies a Distribute call places, with the number it
  // has placed: for a progress line, and may throw to abandon the placement
  // (a stop signal while a million copies are placed).
  void set_every_4096(std::function<void(int64_t placed)> call) { every_4096_ = std::move(call); }

  void AddObstacle(const Obstacle2& obstacle) { obstacles_.push_back(obstacle); }
  // Keeps the obstacles that reach more than `overlap` into heights [lo, hi]
  // (the copies' band, as the physics engines' rule for static shapes): a
  // shelf or lamp shade above the robots does not keep them away.
  void KeepObstaclesReaching(double lo, double hi, double overlap);
  // The environment map's occupied cells in the plane (a grid of squares,
  // the map format's occupied_plane, framework/world_section.h): copies
  // keep `clearance` from each like from an obstacle.
  void SetMapCells(EnvironmentPlaneGrid cells) { map_ = std::move(cells); }
  // A copy placed by other means (a fixed position): later copies keep clear of it.
  void AddBody(double x, double y, double radius);

  // Places up to `count` discs of `radius` wholly inside `region`, each at
  // least `clearance` from every disc already placed and from every
  // obstacle, headings uniform in [-pi, pi) (or all `heading`). Draws from
  // Rng(seed, kPlacementStream + stream). Stops at the first copy that finds
  // no free spot in kMaxAttempts tries: the result then has fewer than `count`
  // poses (the caller reports it). The placed discs are kept.
  std::vector<Placement2> Distribute(const Region2& region, int64_t count, double radius,
                                     double clearance, uint64_t stream,
                                     std::optional<double> heading = std::nullopt);
  // The same, with copy k's disc of radius `radius_of(k)` (at most
  // `max_radius`): copies of one model whose own parameter values change
  // their size. With every radius equal, the same poses as Distribute.
  std::vector<Placement2> Distribute(const Region2& region, int64_t count,
                                     const std::function<double(int64_t)>& radius_of,
                                     double max_radius, double clearance, uint64_t stream,
                                     std::optional<double> heading = std::nullopt);

  // `count` copies on a lattice (a world's `distribute: {lattice: ...}`):
  // `columns` per row (copy k in row k / columns, column k % columns), rows
  // `spacing` apart on a square lattice or spacing * sqrt(3) / 2 apart on a
  // hexagonal one (odd rows shifted by spacing / 2 along x), the block
  // centred in `region`; copy 0 at its lower-left (least x, least y).
  // Headings as Distribute's. The result has fewer than `count` poses when
  // copy k's disc of `radius` leaves the region or touches an obstacle or
  // a placed body (*first_bad = k); bodies are kept only on success.
  std::vector<Placement2> Lattice(const Region2& region, int64_t count, double radius,
                                  double spacing, bool hexagonal, int64_t columns, uint64_t stream,
                                  std::optional<double> heading, int64_t* first_bad);

  // True if a disc at (x, y) of `radius` keeps `clearance` from every body
  // and obstacle (what Distribute checks for each candidate).
  bool IsFree(double x, double y, double radius, double clearance) const;

  size_t body_count() const { return bodies_.size(); }

 private:
  struct Body {
    double x, y, radius;
  };
  // Does a map cell come closer than `keep` to (x, y)?
  bool NearMapCell(double x, double y, double keep) const;
  void Insert(uint32_t body);
  // A grid of cells of at least `cell_size` over [lo_x, hi_x] x [lo_y, hi_y]
  // sized for `bodies` bodies, every body filed in it.
  void Rebuild(double cell_size, double lo_x, double lo_y, double hi_x, double hi_y, size_t bodies);
  // The grid cell index along an axis (may lie outside 0..n-1; clamped to
  // -1 .. 2^50 so that a far coordinate still converts to an integer).
  int64_t CellIndex(double v, double origin) const {
    const double cell = std::floor((v - origin) / cell_size_);
    return static_cast<int64_t>(cell > -1 ? std::min(cell, 0x1p50) : -1.0);
  }

  uint64_t seed_;
  std::function<void(int64_t)> every_4096_;
  std::vector<Body> bodies_;
  std::vector<Obstacle2> obstacles_;
  EnvironmentPlaneGrid map_;  // map cells (empty: none)
  double max_body_radius_ = 0;
  // Bodies by cell of a dense grid over the region being filled (a list per
  // cell: head_ by cell, next_ by body, -1 ends): the cell edge is at least
  // the largest body diameter, so a query looks at a small block of cells.
  // Bodies outside the grid (fixed copies elsewhere) are checked one by one.
  double cell_size_ = 0;
  double grid_x0_ = 0, grid_y0_ = 0;  // the grid's lower-left corner
  int64_t grid_nx_ = 0, grid_ny_ = 0;
  std::vector<int32_t> head_;
  std::vector<int32_t> next_;
  std::vector<uint32_t> outside_;
};

}  // namespace swarmsim
