// The built-in object types, one registration line each, in ObjectType
// order (the order the state hash adds them in). Each is defined in its own
// file of this folder and declared in core_types.h.
#include "framework/types/core_types.h"

#include <iterator>

namespace swarmsim {

std::span<const ObjectTypeDescriptor* const> CoreObjectTypes() {
  static constexpr const ObjectTypeDescriptor* kTypes[] = {
      &kDummyType,           &kShapeType,        &kJointType,
      &kProximitySensorType, &kPluginSensorType, &kCollectionType,
  };
  static_assert(std::size(kTypes) == kBuiltinObjectTypes);
  return kTypes;
}

}  // namespace swarmsim
