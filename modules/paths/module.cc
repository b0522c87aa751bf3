#include "modules/paths/module.h"

#include <cmath>

#include "framework/world.h"
#include "modules/paths/rows.h"

namespace swarmsim::paths {

uint32_t FindFollower(const Scene& scene, uint32_t path_slot, const std::string& name) {
  for (const ObjectId child : scene.children(scene.IdAt(path_slot)))
    if (scene.name(child) == name) return child.index();
  return kNoSlot;
}

void PathsModule::Start(World* world) { Move(&world->scene(), 0.0); }

void PathsModule::Actuate(World* world) { Move(&world->scene(), world->settings().time_step); }

void PathsModule::Move(Scene* scene, double dt) {
  Rows<PathRow>* rows = PathRows(scene);
  if (rows == nullptr || rows->size() == 0) return;
  // Followers by name, again when objects were added, copied or removed.
  if (version_ != scene->structure_version()) {
    followers_.assign(rows->size(), {});
    for (size_t r = 0; r < rows->size(); ++r)
      for (const std::string& name : rows->rows[r].followers)
        followers_[r].push_back(FindFollower(*scene, rows->owners[r], name));
    version_ = scene->structure_version();
  }
  for (size_t r = 0; r < rows->size(); ++r) {
    PathRow& p = rows->rows[r];
    if (!std::isnan(p.requested_position)) {
      p.position = p.requested_position;
      p.requested_position = NAN;
    }
    if (p.followers.empty() && p.velocity == 0) continue;
    const std::vector<uint32_t>& slots = followers_[r];
    // A follower's file pose is its offset in the moving frame.
    if (p.offsets.size() != slots.size()) {
      p.offsets.clear();
      for (const uint32_t slot : slots)
        p.offsets.push_back(slot != kNoSlot ? scene->local_pose_at(slot) : Pose{});
    }
    p.position = p.curve->Normalize(p.position + p.velocity * dt);
    if (slots.empty()) continue;
    const Pose X_PC = p.curve->PoseAt(p.position);
    for (size_t k = 0; k < slots.size(); ++k)
      if (slots[k] != kNoSlot) scene->SetLocalPose(scene->IdAt(slots[k]), X_PC * p.offsets[k]);
  }
}

}  // namespace swarmsim::paths
