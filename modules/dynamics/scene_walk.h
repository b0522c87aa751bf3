// Walks over the scene tree that every dynamics engine's Build makes the same
// way: which shapes exist, which body carries an object, which body hangs
// below a joint or force sensor. Engine-neutral (slots and rows only); the
// engines map the slots they get to their own bodies.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "modules/force_sensor/force_sensor.h"

namespace swarmsim::dynamics {

// The shape at a slot, or null if the slot holds no live shape.
inline const ShapeData* ShapeAt(const Scene& scene, uint32_t slot) {
  if (!scene.alive_at(slot) || scene.type_at(slot) != ObjectType::kShape) return nullptr;
  return &scene.shapes()[scene.row_at(slot)];
}

// The first dynamic shape below `slot`, depth first with children in order,
// not across a joint or force sensor (what a joint or sensor holds): its
// slot, or -1.
inline int32_t FirstDynamicShapeBelow(const Scene& scene, uint32_t slot) {
  ObjectType sensor_type = ObjectType::kJoint;  // stays kJoint when there is no such type
  force_sensor::FindType(scene, &sensor_type);
  std::vector<uint32_t> stack;
  const std::vector<ObjectId> children = scene.children(scene.IdAt(slot));
  for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(it->index());
  while (!stack.empty()) {
    const uint32_t c = stack.back();
    stack.pop_back();
    if (scene.type_at(c) == ObjectType::kJoint || scene.type_at(c) == sensor_type) continue;
    const ShapeData* shape = ShapeAt(scene, c);
    if (shape && shape->dynamic) return static_cast<int32_t>(c);
    const std::vector<ObjectId> grand = scene.children(scene.IdAt(c));
    for (auto it = grand.rbegin(); it != grand.rend(); ++it) stack.push_back(it->index());
  }
  return -1;
}

// The body of the nearest ancestor of `slot` that has one: body_of (slots)
// maps a slot to its body, `none` where it has none. `none` if no ancestor
// has a body.
template <class Body>
Body NearestBodyAbove(const Scene& scene, const std::vector<Body>& body_of, uint32_t slot,
                      Body none) {
  for (int32_t p = scene.parent_at(slot); p >= 0; p = scene.parent_at(static_cast<uint32_t>(p)))
    if (body_of[p] != none) return body_of[p];
  return none;
}

// The force sensors' rows (modules/force_sensor) in their owners' slot
// order, like the joints, so that an engine's joint list is the same every
// build.
inline std::vector<uint32_t> ForceSensorRowsInSlotOrder(const Scene& scene) {
  const Rows<ForceSensorData>* sensors = force_sensor::RowsOf(scene);
  if (sensors == nullptr) return {};
  const std::vector<uint32_t>& owners = sensors->owners;
  std::vector<uint32_t> rows(owners.size());
  for (uint32_t r = 0; r < rows.size(); ++r) rows[r] = r;
  std::sort(rows.begin(), rows.end(),
            [&](uint32_t a, uint32_t b) { return owners[a] < owners[b]; });
  return rows;
}

// The scene path of the object in `slot`, for messages.
inline std::string PathAt(const Scene& scene, uint32_t slot) {
  return scene.PathOf(scene.IdAt(slot));
}

// Refuses a body whose pose is not finite: "<engine>: shape '/a/b' has a
// non-finite pose".
inline void ThrowIfNotFinite(std::string_view engine, const Scene& scene, uint32_t slot,
                             const Pose& X) {
  for (double v : {X.p.x, X.p.y, X.p.z, X.q.w, X.q.x, X.q.y, X.q.z})
    if (!std::isfinite(v)) {
      std::string message(engine);
      message += ": shape '";
      message += PathAt(scene, slot);
      message += "' has a non-finite pose";
      throw Error(message);
    }
}

}  // namespace swarmsim::dynamics
