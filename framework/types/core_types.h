// The built-in object types' descriptors (one file each in this folder),
// for core_types.cc's list.
#pragma once

#include "framework/object_type.h"

namespace swarmsim {

extern const ObjectTypeDescriptor kDummyType;
extern const ObjectTypeDescriptor kShapeType;
extern const ObjectTypeDescriptor kJointType;
extern const ObjectTypeDescriptor kPluginSensorType;
extern const ObjectTypeDescriptor kCollectionType;

}  // namespace swarmsim
