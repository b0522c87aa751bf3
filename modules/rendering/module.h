// The rendering module: in the sense phase (order 150: after proximity,
// before plugin sensors), every vision sensor that is due renders the scene
// as it stands, sensors in parallel, each image drawn by one thread's GL
// context so that it does not depend on the thread count.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "framework/module.h"
#include "modules/rendering/geometry.h"

namespace swarmsim::rendering {

ModuleDescriptor RenderingModuleDescriptor();

class RenderingModule final : public Module {
 public:
  void Start(World* world) override;
  void Sense(World* world) override;
  // Snapshots (framework/world_state.h): vision sensors' and cameras' images
  // are not saved, so a world with them is refused; without them it is idle.
  bool SaveState(const World& world, StateWriter* out) const override;

 private:
  void RenderDue(World* world, bool all);

  // One draw list per level of detail the due sensors need, built once a step.
  std::vector<std::pair<int, DrawList>> lists_;
  uint64_t version_ = UINT64_MAX;              // the scene structure the masks are for
  std::vector<std::vector<uint8_t>> visible_;  // per sensor row: slots it sees (empty: all)
};

// The view of a vision sensor or camera at slot `slot` with `lens`.
View ViewOf(const Scene& scene, uint32_t slot, const struct Lens& lens, bool depth);

}  // namespace swarmsim::rendering
