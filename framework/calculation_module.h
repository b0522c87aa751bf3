// Calculation modules that work on calculation objects (paper §2.2): IK
// groups today, later minimum-distance objects or path followers. A world
// creates each module by registered name on first use (World::calculation)
// and calls it in the actuate phase. A module follows the objects its
// calculation objects refer to through duplication and removal (paper §2.3:
// copies of a model are fully functional, deleted models leave nothing).
#pragma once

#include <span>

#include "framework/scene.h"

namespace swarmsim {

class StateHasher;
class World;

class CalculationModule : public SceneListener {
 public:
  ~CalculationModule() override = default;
  // Runs in the actuate phase, after deferred writes, before joints move
  // toward their targets. Robots may be handled concurrently through
  // world->scheduler(); results must not depend on the thread count.
  virtual void Actuate(World* world) = 0;
  // Folds state that is not in the scene and changes the future into the hash.
  virtual void HashState(StateHasher* /*hasher*/) const {}
};

}  // namespace swarmsim
