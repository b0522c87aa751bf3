// Paint nozzles (the paper's paint nozzle): an object that marks the floor
// under it in the paint layer each step while enabled. The paint module's
// public header: the nozzle's rows and the module's registration; the layer
// (paint_layer.h) is the folder's own, and others read its image through
// World::floor_layer (framework/floor_layer.h).
#pragma once

#include <memory>

#include "framework/math.h"

namespace swarmsim {

class ModuleRegistry;
struct WorldSectionDescriptor;

inline constexpr const char* kPaintNozzleTypeName = "paint_nozzle";

struct PaintNozzleData {      // 40 bytes
  Vec3 color{0.1, 0.1, 0.8};  // RGB in [0, 1]
  double radius = 0.02;       // m, of the painted disc
  bool enabled = true;
};

namespace paint {

// Registers the paint_nozzle object type (with its Lua area) and the
// "paint" module (modules/builtin.cc).
void Register(ModuleRegistry* registry);
// The world-file section `paint:` that makes the layer
// (ModuleRegistry::RegisterWorldSection).
std::shared_ptr<const WorldSectionDescriptor> PaintSection();

}  // namespace paint
}  // namespace swarmsim
