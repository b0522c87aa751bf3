// The `path` object type's row (objects.cc) and how the module and the Lua
// area find it. Internal to modules/paths.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "framework/math.h"
#include "framework/scene.h"
#include "modules/paths/curve.h"

namespace swarmsim::paths {

inline constexpr const char* kTypeName = "path";
inline constexpr const char* kModuleName = "paths";

struct PathRow {
  // Settings.
  std::shared_ptr<const PathCurve> curve;  // shared by copies (scaled: one copy per scale)
  std::vector<std::string> followers;      // names of the path's children that ride it
  std::string where;                       // "file:line:column" of `followers`, for errors
  // State: where the followers are along the curve and how fast they move.
  double position = 0;  // m, arc length
  double velocity = 0;  // m/s
  // sim.setPathPosition's request, applied in the actuate phase (NaN: none),
  // so `position` changes only there and any robot may read it.
  double requested_position = NAN;
  // The followers' poses in the frame moving along the curve (their file
  // poses, kept when first moved; one per follower).
  std::vector<Pose> offsets;
};

// The scene's path rows, or null if the type is not registered.
inline Rows<PathRow>* PathRows(Scene* scene) {
  ObjectType type;
  if (!scene->FindType(kTypeName, &type)) return nullptr;
  return static_cast<Rows<PathRow>*>(scene->rows(type));
}

}  // namespace swarmsim::paths
