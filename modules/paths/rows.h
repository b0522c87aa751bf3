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
inline constexpr const char* kConveyorTypeName = "conveyor";
inline constexpr const char* kModuleName = "paths";

struct PathRow {
  // Settings.
  std::shared_ptr<const PathCurve> curve;  // shared by copies (scaled: one copy per scale)
  std::vector<std::string> followers;      // names of the path's children that ride it
  std::string where;                       // "file:line:column" of `followers`, for errors
  std::vector<double> pauses;              // s, per point (or empty): followers stop there
  // State: where the followers are along the curve and how fast they move.
  double position = 0;  // m, arc length
  double velocity = 0;  // m/s
  // sim.setPathPosition's request, applied in the actuate phase (NaN: none),
  // so `position` changes only there and any robot may read it.
  double requested_position = NAN;
  double pause_left = 0;  // s: the followers wait at a point this much longer
  // The followers' poses in the frame moving along the curve (their file
  // poses, kept when first moved; one per follower).
  std::vector<Pose> offsets;
};

// A conveyor (conveyor.cc): a belt along a curve, made of box segments (its
// children `belt0`, `belt1`, ..., made when the world starts) whose surface
// slides at `speed` along the curve, carrying dynamic objects lying on it.
struct ConveyorRow {
  // Settings.
  std::shared_ptr<const PathCurve> curve;  // the belt's top centre line, in its frame
  double width = 0.3;                      // m, across the belt
  double thickness = 0.05;                 // m, below the curve
  double segment_length = 0.1;             // m: the longest segment along a smooth curve
  double friction = 0.7;
  Vec3 color{0.2, 0.2, 0.22};
  // State.
  double speed = 0;              // m/s along the curve (negative: backwards)
  double requested_speed = NAN;  // sim.setConveyorSpeed's, applied in the actuate phase
  double applied_speed = NAN;    // what the segments' surfaces carry (NaN: not yet)
  uint32_t segments = 0;         // belt segments made (0: not yet; copies keep theirs)
  // Per segment: its turn per metre about its z axis (rad/m, positive to
  // the left), so a segment on a bend turns what it carries with the bend.
  std::shared_ptr<const std::vector<double>> curvature;
};

// The scene's path rows, or null if the type is not registered.
inline Rows<PathRow>* PathRows(Scene* scene) {
  ObjectType type;
  if (!scene->FindType(kTypeName, &type)) return nullptr;
  return static_cast<Rows<PathRow>*>(scene->rows(type));
}

// The scene's conveyor rows, or null if the type is not registered.
inline Rows<ConveyorRow>* ConveyorRows(Scene* scene) {
  ObjectType type;
  if (!scene->FindType(kConveyorTypeName, &type)) return nullptr;
  return static_cast<Rows<ConveyorRow>*>(scene->rows(type));
}

// The name of a conveyor's k-th belt segment ("belt3").
inline std::string BeltSegmentName(uint32_t k) { return "belt" + std::to_string(k); }

}  // namespace swarmsim::paths
