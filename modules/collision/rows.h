// The rows of the collision module's object types (objects.cc): distance
// and collision objects, V-REP's calculation objects between two entities
// (framework/collections.h). Internal to modules/collision.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "framework/handle.h"
#include "framework/math.h"
#include "modules/collision/geometry.h"

namespace swarmsim::collision {

struct DistanceRow {
  // Settings.
  std::string entity[2];        // as the file gives them (`between`)
  std::string where;            // "file:line:column" of `between`, for errors
  double threshold = INFINITY;  // m: nothing farther is measured
  bool record = true;           // into metrics.csv
  // The reading, after each step.
  bool found = false;  // something within the threshold
  double distance = INFINITY;
  Vec3 p1, p2;      // closest points, world frame
  ObjectId o1, o2;  // their shapes (o2 null: the environment map)
  // Last step's closest pair (slots), measured first next step.
  uint32_t hint1 = kNoSlot, hint2 = kNoSlot;
};

struct CollisionRow {
  std::string entity[2];
  std::string where;
  int contacts = 0;  // contact points kept (the collision contour), 0..64
  bool record = true;
  bool colliding = false;
  ObjectId o1, o2;
  std::vector<Vec3> contact_points;  // world frame
};

}  // namespace swarmsim::collision
