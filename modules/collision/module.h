// The collision module's instance (internal to modules/collision).
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "framework/collections.h"
#include "framework/module.h"
#include "modules/collision/geometry.h"

namespace swarmsim::collision {

inline constexpr const char* kModuleName = "collision";

class CollisionModule final : public Module {
 public:
  // Snapshots (framework/world_state.h): its objects' rows (no save_rows) make
  // World::SaveState refuse while the world has any; without them it is idle.
  bool SaveState(const World&, StateWriter*) const override { return true; }
  void Start(World* world) override;
  void AfterPhysics(World* world) override;
  void Record(const World& world, std::vector<MetricSample>* out) override;

  // The geometry, refreshed if the scene's structure changed since (scripts'
  // immediate queries; safe from robots running in parallel).
  const Geometry& Fresh(const World& world);

 private:
  // One distance or collision object's work, resolved from its entities.
  struct Job {
    bool distance = true;  // else collision
    uint32_t row = 0;
    std::vector<uint32_t> a;  // shapes
    EntitySpec::Kind kind = EntitySpec::kPath;
    std::vector<uint32_t> b;  // shapes, for kPath
  };
  static bool HasObjects(Scene* scene);
  void Refresh(const World& world);
  void Resolve(const Scene& scene);
  void Run(Scene* scene, const Job& job);
  void Compute(World* world);

  Geometry geometry_;
  std::mutex mutex_;
  std::atomic<uint64_t> version_{UINT64_MAX};  // the scene structure geometry_ follows
  std::atomic<uint64_t> step_{UINT64_MAX};     // and the step whose poses it has
  uint64_t jobs_version_ = UINT64_MAX;
  std::vector<std::vector<Job>> jobs_;  // by robot, then the scene's last
  bool any_jobs_ = false;
};

}  // namespace swarmsim::collision
