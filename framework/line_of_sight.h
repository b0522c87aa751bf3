// A narrow service: is the straight segment between two points clear of the
// static environment? World holds one (World::line_of_sight()) that the
// proximity module provides when it starts (its static index answers);
// range messages with line of sight (messaging.cc) and the blob cameras'
// occlusion by the environment map ask it. Without a provider nothing
// blocks.
#pragma once

#include "framework/math.h"

namespace swarmsim {

class LineOfSight {
 public:
  virtual ~LineOfSight() = default;
  // Does a static obstacle (a shape of no robot that is not dynamic, or a
  // box of the Scene's environment map) cross the segment from a_W to b_W
  // (world frame, m)? Thread-safe: called concurrently in the message
  // delivery and the sense phase.
  virtual bool SegmentBlocked(const Vec3& a_W, const Vec3& b_W) const = 0;
};

}  // namespace swarmsim
