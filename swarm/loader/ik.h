// IK groups in model files (the `ik_groups:` key, worlds/README.md): read
// with the model's values, then added to the world for the first copy of
// the model; the "ik" calculation module copies them with each duplicate.
#pragma once

#include <string>
#include <vector>

#include "modules/kinematics/ik_groups.h"
#include "swarm/loader/model.h"
#include "swarm/loader/values.h"

namespace swarmsim {
class World;
}

namespace swarmsim::loader {

struct IkTipDef {
  Field tip, target, base;  // object paths in the model ("leg1/footTip"); base optional
  uint8_t constraints = kIkPosition;
};

struct IkAvoidDef {
  std::vector<Field> links;  // object paths in the model
  IkAvoidSpec spec;          // obstacle, distance, where
};

struct IkGroupDef {
  Field field;       // the group's mapping, for messages
  IkGroupSpec spec;  // settings; objects filled in by AddIkGroups
  std::vector<IkTipDef> tips;
  std::vector<std::pair<Field, double>> weights;  // joint path, weight
  std::vector<IkAvoidDef> avoid;
};

std::vector<IkGroupDef> ReadIkGroups(const ModelFile& model, const ValueReader& values);

// Resolves the paths against the copy rooted at `root` (built from `spec`)
// and adds the groups to `world`.
void AddIkGroups(const ModelFile& model, const std::vector<IkGroupDef>& groups,
                 const ObjectSpec& spec, ObjectId root, World* world);

}  // namespace swarmsim::loader
