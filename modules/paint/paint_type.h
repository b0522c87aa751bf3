// Internal to modules/paint: the paint_nozzle type's descriptor
// (paint_nozzle_type.cc), for the module's registration (paint_section.cc).
#pragma once

#include "framework/object_type.h"

namespace swarmsim::paint {

extern const ObjectTypeDescriptor kPaintNozzleType;

}  // namespace swarmsim::paint
