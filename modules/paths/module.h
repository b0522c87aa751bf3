// The paths module's instance: moves each path's followers along it in the
// actuate phase (internal to modules/paths).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "framework/module.h"

namespace swarmsim::paths {

inline constexpr uint32_t kNoSlot = UINT32_MAX;

// The slot of the child of the path at `path_slot` named `name`, or kNoSlot.
uint32_t FindFollower(const Scene& scene, uint32_t path_slot, const std::string& name);

class PathsModule final : public Module {
 public:
  // Snapshots (framework/world_state.h): its objects' rows (no save_rows) make
  // World::SaveState refuse while the world has any; without them it is idle.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  // Places the followers at their paths' starting positions; makes the
  // conveyors' belts and sets their surfaces moving.
  void Start(World* world) override;
  // Advances each path's position by velocity x dt (clamped at the ends of
  // an open path, wrapped on a closed one) and moves its followers there;
  // applies the conveyors' new speeds to their belts' surfaces. Rows in
  // order, serially: cheap, and the same for any thread count.
  void Actuate(World* world) override;

 private:
  void Move(Scene* scene, double dt);
  void DriveConveyors(Scene* scene);

  uint64_t version_ = UINT64_MAX;                 // the scene structure followers_ follows
  std::vector<std::vector<uint32_t>> followers_;  // by path row: the followers' slots
  uint64_t belts_version_ = UINT64_MAX;           // the scene structure belts_ follows
  std::vector<std::vector<uint32_t>> belts_;      // by conveyor row: the segments' slots
};

}  // namespace swarmsim::paths
