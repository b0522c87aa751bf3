// What the paths module's files share about its object types (internal to
// modules/paths): reading and scaling curves, the types' descriptors and
// their Lua areas.
#pragma once

#include <cstdint>
#include <memory>

#include "framework/object_type.h"
#include "modules/paths/curve.h"

namespace swarmsim::paths {

struct ConveyorRow;

// A curve from an object's `points`, `interpolation` and `closed` keys
// (objects.cc); errors name the key's file:line:column.
std::shared_ptr<const PathCurve> ReadCurve(const ObjectReader& reader);
// The curve scaled by s, one copy per curve per ScaleSubtree call.
std::shared_ptr<const PathCurve> ScaledCurve(const std::shared_ptr<const PathCurve>& curve,
                                             double s, ScaleContext* context);

// The `conveyor` type (conveyor.cc).
std::shared_ptr<const ObjectTypeDescriptor> ConveyorType();

// Makes the belt segments of the conveyor at `slot` (its children belt0,
// belt1, ...; conveyor.cc) and counts them in row->segments.
void BuildBelt(Scene* scene, uint32_t slot, ConveyorRow* row);

// The types' Lua areas (lua_api_paths.cc).
void RegisterPathApi(lua_State* L);
void RegisterConveyorApi(lua_State* L);

}  // namespace swarmsim::paths
