// The `ik_groups:` key of model files and models entries (worlds/README.md),
// a model-file section (framework/model_section.h) the kinematics module
// registers: read with the model's values, added to the world for each copy
// built from the model's description; the "ik" module copies them with
// each duplicate.
#pragma once

#include <memory>

#include "framework/model_section.h"

namespace swarmsim::kinematics {

std::shared_ptr<const ModelSectionDescriptor> IkGroupsSection();

}  // namespace swarmsim::kinematics
