// The built-in object types, one registration line each, in ObjectType
// order (the order the state hash adds them in). Each is defined in its own
// file of this folder and declared in core_types.h.
#include "framework/types/core_types.h"

#include <cstring>
#include <iterator>

namespace swarmsim {

std::span<const ObjectTypeDescriptor* const> CoreObjectTypes() {
  static constexpr const ObjectTypeDescriptor* kTypes[] = {
      &kDummyType, &kShapeType, &kJointType, &kPluginSensorType, &kCollectionType,
  };
  static_assert(std::size(kTypes) == kBuiltinObjectTypes);
  return kTypes;
}

std::vector<size_t> ListingOrder(std::span<const ObjectTypeDescriptor* const> types) {
  std::vector<size_t> order;
  order.reserve(types.size());
  for (size_t t = 0; t < types.size(); ++t) {
    auto at = order.end();
    if (const char* after = types[t]->listed_after)
      for (auto it = order.begin(); it != order.end(); ++it)
        if (std::strcmp(types[*it]->name, after) == 0) {
          at = it + 1;
          break;
        }
    order.insert(at, t);
  }
  return order;
}

}  // namespace swarmsim
