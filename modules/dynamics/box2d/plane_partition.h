// The box2d backend's world: the plane cut into regions (strips), each its own
// PlaneWorld, stepped concurrently (see "Partitions" in box2d_backend.h for
// the model). With one region it is exactly one PlaneWorld. Internal.
#pragma once

#include <array>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "framework/dynamics_backend.h"
#include "modules/dynamics/box2d/plane_world.h"

namespace swarmsim::box2d {

class PartitionedPlaneWorld {
 public:
  // For EngineBackend (engine_backend.h).
  using Options = box2d::Options;
  static constexpr std::string_view kName = "box2d";
  static constexpr bool kIdleWithoutSubsteps = false;

  // `auto` (settings.partitions 0): one region per this many bodies...
  static constexpr int kAutoBodiesPerRegion = 250;
  // ...and at most this many regions.
  static constexpr int kAutoMaxRegions = 1024;
  // Up to this many regions are strips across the longer side; more are a
  // grid: columns across the longer side, each cut into the same number of
  // rows (so regions stay near square and ghosts few).
  static constexpr int kMaxStrips = 16;

  PartitionedPlaneWorld(const Options& options, const DynamicsSettings& settings);
  ~PartitionedPlaneWorld();

  void Build(const Scene& scene);
  void MarkJoints(Scene* /*scene*/) const {}
  // Also places again the ground fixtures of static shapes that moved.
  void SyncFromScene(const Scene& scene, double duration);
  // Commands, then (with regions) migration and the ghost sets for the step.
  void ReadCommands(const Scene& scene);
  void Substep(double dt, double fraction);
  void WriteBack(Scene* scene);
  void Hash(StateHasher* hasher) const;
  int body_count() const;

  // Regions in use (1 when the world could not be split), and ghosts now.
  int region_count() const { return static_cast<int>(regions_.size()); }
  // Columns and rows of the grid (strips: region_count() columns of 1 row).
  int column_count() const { return static_cast<int>(borders_.size()) + 1; }
  int row_count() const { return rows_; }
  int ghost_count() const;

 private:
  // The column holding a position along the axis, and the row of column
  // `column` holding a position across it; the region of a point (Box2D
  // units). Regions are numbered column by column.
  int ColumnOf(double along) const;
  int RowOf(int column, double across) const;
  int RegionOf(const b2Vec2& p) const;
  // Calls fn(region) for every region, concurrently on the run's workers
  // when there are several (each call touches its region only).
  template <class Fn>
  void ForEachRegion(Fn&& fn);
  // Bodies whose centre left their region move to the one holding it, in
  // region and body order.
  void Migrate();
  // Each body within reach of another region gets a ghost there.
  void UpdateGhosts();

  Options options_;
  DynamicsSettings settings_;
  std::vector<std::unique_ptr<PlaneWorld>> regions_;
  int axis_ = 0;                 // 0: columns across x, 1: across y
  std::vector<double> borders_;  // (columns - 1), ascending, Box2D units, along axis_
  int rows_ = 1;                 // rows per column
  // Per column, (rows - 1) ascending borders across axis_ (empty with one row).
  std::vector<std::vector<double>> row_borders_;
  double max_radius_ = 0;  // largest body's bounding radius, Box2D units
  double duration_ = 0;    // s, of the current step
  // Published body states, one per body (not per scene slot: a robot's
  // sensors have none): substeps read one, write the other.
  std::array<std::vector<PlaneBodyState>, 2> states_;
  std::vector<uint32_t> state_of_slot_;  // by scene slot: the body's row in states_
  // Per-step scratch, by region (kept for their capacity): bodies leaving
  // (body, region), ghosts wanted elsewhere (region, want), ghosts wanted here.
  using Want = std::pair<uint32_t, const b2Body*>;  // (slot, owner body)
  std::vector<std::vector<std::pair<uint32_t, int>>> leaving_;
  std::vector<std::vector<std::pair<int, Want>>> needs_;
  std::vector<std::vector<Want>> wanted_;
  int current_ = 0;
  // Static shapes that moved: their ground fixtures out of every region, and
  // in again where they are now, in the regions they reach.
  void MoveObstacles(const Scene& scene);
  dynamics::ObstaclePoses obstacle_poses_;  // as the staging world built them
  HeightRange dynamic_range_{0, 0};         // the staging world's
  // Per region, the box its ground copies come from (CopyGround's lo, hi,
  // cross_lo, cross_hi along axis_), Box2D units.
  std::vector<std::array<double, 4>> ground_reach_;
  std::vector<uint32_t> moved_;  // scratch: slots of the static shapes that moved
};

}  // namespace swarmsim::box2d
