// The collision module's geometry (internal to modules/collision; FCL types
// stay in geometry.cc): one FCL collision object per shape of the scene,
// its geometry shared between copies (one BVH per mesh asset, one primitive
// per kind and size), and two broad phases: the environment (static shapes
// and the map's boxes: built when they change, a static shape that a script
// or a path moved updated in place) and the moving shapes (refit each step).
//
// Queries read only; Refresh() writes. Queries from scripts run robots in
// parallel between refreshes.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "framework/collections.h"
#include "framework/math.h"

namespace swarmsim {
class Scene;
}

namespace swarmsim::collision {

// A query's slot for a box of the environment map (not a scene object).
inline constexpr uint32_t kMapSlot = std::numeric_limits<uint32_t>::max() - 1;
inline constexpr uint32_t kNoSlot = std::numeric_limits<uint32_t>::max();

// The second side of a query: shapes (`slots`, ascending), the environment,
// or everything but the first side.
struct Target {
  EntitySpec::Kind kind = EntitySpec::kPath;
  std::span<const uint32_t> slots;
};

struct DistanceAnswer {
  bool found = false;  // something within the threshold
  double distance = std::numeric_limits<double>::infinity();
  Vec3 p1, p2;  // closest points (world), on the first side and on the second
  uint32_t s1 = kNoSlot, s2 = kNoSlot;  // their shapes' slots (s2: kMapSlot for the map)
};

struct CollisionAnswer {
  bool colliding = false;
  uint32_t s1 = kNoSlot, s2 = kNoSlot;  // the first colliding pair found
  std::vector<Vec3> contacts;           // world points, when asked for
};

class Geometry {
 public:
  Geometry();
  ~Geometry();
  Geometry(const Geometry&) = delete;
  Geometry& operator=(const Geometry&) = delete;

  // Follows the scene: rebuilds the objects when its structure changed,
  // else moves the moving shapes' objects to their poses and refits.
  void Refresh(const Scene& scene);

  // The shapes among `slots` (ascending, as given).
  std::vector<uint32_t> ShapesOf(const Scene& scene, std::span<const uint32_t> slots) const;

  // Minimum distance between the shapes `a` and `b` up to `threshold`.
  // `hint` (the last answer's pair, or kNoSlot) is measured first and
  // bounds the search (temporal coherence); `coherent` false ignores it.
  DistanceAnswer Distance(std::span<const uint32_t> a, const Target& b, double threshold,
                          uint32_t hint_a, uint32_t hint_b) const;
  // Do `a` and `b` collide? Up to `max_contacts` contact points (0: none).
  CollisionAnswer Collide(std::span<const uint32_t> a, const Target& b, int max_contacts) const;

  size_t object_count() const;

 private:
  friend class Probe;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Shapes moved together as one rigid body to poses other than the scene's,
// checked against the rest (path planning, modules/planning): a frame F
// carries them, each keeping its pose in F as the scene has it now. Reads
// the geometry only (refresh it first, and not while probing), so probes
// of different robots run in parallel; one probe is for one thread.
class Probe {
 public:
  // `shapes`: ascending slots of shapes of `geometry`; X_WF: the frame's
  // pose now.
  Probe(const Geometry& geometry, const Scene& scene, std::span<const uint32_t> shapes,
        const Pose& X_WF);
  ~Probe();
  Probe(const Probe&) = delete;
  Probe& operator=(const Probe&) = delete;

  // Do the shapes, with their frame at X_WF, collide with `b`? The shapes
  // themselves are never part of `b`.
  bool Collides(const Pose& X_WF, const Target& b);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmsim::collision
