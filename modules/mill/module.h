// The mill module's instance (internal to modules/mill).
//
// After physics (order 40: after the dynamics moved the mills, before the
// collision module's checks at 50 and the next step's sensors, as V-REP's
// main script handles mills right after dynamics and before collisions and
// distances), every enabled mill cuts:
// 1. each robot's mills, robots in parallel, list the voxels of every
//    cuttable near them whose centres are inside their volume, reading the
//    blocks as the step found them (no writes);
// 2. the lists are applied one mill after the other, robots in index order
//    then the scene's mills, each robot's in row order: a voxel goes to the
//    first mill that lists it, whatever the thread count;
// 3. the same mills, in the same order, cut the environment map when their
//    volume's bounding box meets the map's bounds; when anything went, the
//    scene gets the new map (Scene::set_environment: a new pointer).
// A world without mills pays one structure-version check per step.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "framework/module.h"
#include "framework/spatial_grid.h"
#include "modules/mill/map_cut.h"
#include "modules/mill/rows.h"

namespace swarmsim::mill {

inline constexpr const char* kModuleName = "mill";

// Voxels all of a world's cuttables may hold together (8 per byte): a clear
// error past it, before anything is allocated.
inline constexpr double kMaxWorldVoxels = 4e9;

class MillModule final : public Module {
 public:
  // Snapshots (framework/world_state.h): its objects' rows (no save_rows) make
  // World::SaveState refuse while the world has any; without them it is idle.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  explicit MillModule(World* world) : world_(world) {}
  void AfterPhysics(World* world) override;
  void Record(const World& world, std::vector<MetricSample>* out) override;
  // mill.csv: every mill's removed volume and every cuttable's voxels left.
  void WriteOutputs(const std::filesystem::path& dir) const override;
  void ListOutputs(std::vector<OutputFile>* out) const override;
  // The voxels cut out of the map so far (the cuttables' are in their rows).
  void HashState(StateHasher* hasher) const override;
  void OnSubtreeRemoved(const Scene& scene, std::span<const uint32_t> slots) override;

  // Voxels removed from the environment map so far.
  int64_t map_removed_voxels() const { return map_removed_voxels_; }

 private:
  // One cuttable's voxels, by its object's slot.
  struct Block {
    uint64_t id = 0;  // ObjectId::ToInteger of its cuttable (a reused slot is a new block)
    std::vector<uint64_t> bits;  // 1: material; voxel (x, y, z) at (z * ny + y) * nx + x
    bool Has(uint32_t i) const { return (bits[i >> 6] >> (i & 63)) & 1; }
    void Clear(uint32_t i) { bits[i >> 6] &= ~(uint64_t{1} << (i & 63)); }
  };
  // The voxels of one cuttable a mill found inside its volume.
  struct Found {
    uint32_t cuttable_row;
    std::vector<uint32_t> voxels;
  };
  void Refresh(Scene* scene);
  void EnsureBlocks(Scene* scene);
  void Find(const Scene& scene, uint32_t mill_row);
  // One cuttable's voxels inside a mill's volume (Find's inner loop).
  static void FindIn(const CuttableRow& cut, const Block& block, const Volume& volume,
                     const Pose& X_CM, std::vector<uint32_t>* voxels);
  void Apply(Scene* scene, uint32_t mill_row);
  void CutMap(Scene* scene);

  World* world_;
  uint64_t version_ = UINT64_MAX;  // the scene structure the lists below follow
  bool have_types_ = false;
  ObjectType mill_type_{}, cuttable_type_{};
  bool any_mills_ = false;
  std::vector<std::vector<uint32_t>> mills_;    // mill rows by robot, then the scene's last
  std::vector<std::unique_ptr<Block>> blocks_;  // by slot (null: not a cuttable's yet)
  std::vector<std::vector<Found>> found_;       // by mill row, this step
  std::vector<Vec3> centres_;                   // cuttables' centres, world (cuttable rows)
  std::vector<double> radii_;                   // and bounding radii
  std::vector<GridItem> items_;                 // (cuttable rows)
  SpatialGrid grid_;                            // the cuttables' spheres in the plane
  MapCutter map_cutter_;
  int64_t map_removed_voxels_ = 0;
};

}  // namespace swarmsim::mill
