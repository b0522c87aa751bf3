// Object types a plugin registers (plugin_api.h, ABI 4): each object's row
// is one number per declared key, read from model files with its default
// and range, scaled by the key's length power, copied whole and hashed.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "framework/handle.h"
#include "framework/plugin_api.h"

namespace swarmsim {

class Scene;
struct ObjectTypeDescriptor;

// A descriptor for the type `name` with `keys` (copied). Throws
// swarmsim::Error for a key without a name or a default outside its range.
std::shared_ptr<const ObjectTypeDescriptor> MakePluginObjectType(
    const std::string& name, const std::string& description,
    const std::vector<SwarmsimObjectKey>& keys);

// The values of `object` if it is of a plugin's type; null otherwise.
const std::vector<double>* PluginObjectValues(const Scene& scene, ObjectId object);

}  // namespace swarmsim
