#include "modules/paths/module.h"

#include <algorithm>
#include <cmath>

#include "framework/world.h"
#include "modules/paths/rows.h"
#include "modules/paths/types.h"

namespace swarmsim::paths {

namespace {

// Moves a path's position by velocity x dt, stopping at the first point
// with a pause on the way (then waiting there, whole steps, before going on).
void Advance(PathRow* p, double dt) {
  if (p->pause_left > 0) {
    p->pause_left -= dt;
    if (p->pause_left < 1e-9) p->pause_left = 0;  // (0.5 s is five steps of 0.1 s)
    return;
  }
  const double from = p->position, to = from + p->velocity * dt;
  const PathCurve& curve = *p->curve;
  if (!p->pauses.empty() && dt > 0 && p->velocity != 0) {
    // The nearest paused point in (from, to] (or [to, from) backwards),
    // counting a closed path's points once more a lap ahead and behind.
    const double length = curve.length();
    double best = NAN;
    for (size_t i = 0; i < p->pauses.size(); ++i) {
      if (!(p->pauses[i] > 0)) continue;
      for (const double lap : {-1.0, 0.0, 1.0}) {
        if (lap != 0 && !curve.closed()) continue;
        const double s = curve.LengthAtPoint(i) + lap * length;
        const bool ahead = p->velocity > 0 ? s > from && s <= to : s < from && s >= to;
        if (ahead && (std::isnan(best) || std::abs(s - from) < std::abs(best - from))) {
          best = s;
          p->pause_left = p->pauses[i];
        }
      }
    }
    if (!std::isnan(best)) {
      p->position = curve.Normalize(best);
      return;
    }
  }
  p->position = curve.Normalize(to);
}

}  // namespace

uint32_t FindFollower(const Scene& scene, uint32_t path_slot, const std::string& name) {
  for (const ObjectId child : scene.children(scene.IdAt(path_slot)))
    if (scene.name(child) == name) return child.index();
  return kNoSlot;
}

void PathsModule::Start(World* world) {
  Scene* scene = &world->scene();
  if (Rows<ConveyorRow>* conveyors = ConveyorRows(scene)) {
    // Belts of conveyors loaded from files (a copy made later has its own).
    for (size_t r = 0; r < conveyors->size(); ++r)
      if (conveyors->rows[r].segments == 0)
        BuildBelt(scene, conveyors->owners[r], &conveyors->rows[r]);
    if (conveyors->size() > 0) scene->UpdateWorldPoses();
  }
  DriveConveyors(scene);
  Move(scene, 0.0);
  // The followers' world poses where Move put them: what the modules that
  // observe the start (the first frame, step 0's graph sample) and the
  // first sense phase see.
  if (PathRows(scene) != nullptr && PathRows(scene)->size() > 0) scene->UpdateWorldPoses();
}

void PathsModule::Actuate(World* world) {
  DriveConveyors(&world->scene());
  Move(&world->scene(), world->settings().time_step);
}

void PathsModule::DriveConveyors(Scene* scene) {
  Rows<ConveyorRow>* rows = ConveyorRows(scene);
  if (rows == nullptr || rows->size() == 0) return;
  // The belts' segments by name, again when objects were added, copied or removed.
  if (belts_version_ != scene->structure_version()) {
    belts_.assign(rows->size(), {});
    for (size_t r = 0; r < rows->size(); ++r)
      for (uint32_t k = 0; k < rows->rows[r].segments; ++k) {
        const uint32_t slot = FindFollower(*scene, rows->owners[r], BeltSegmentName(k));
        if (slot != kNoSlot && scene->type_at(slot) == ObjectType::kShape)
          belts_[r].push_back(slot);
      }
    belts_version_ = scene->structure_version();
  }
  for (size_t r = 0; r < rows->size(); ++r) {
    ConveyorRow& c = rows->rows[r];
    if (!std::isnan(c.requested_speed)) {
      c.speed = c.requested_speed;
      c.requested_speed = NAN;
    }
    if (c.applied_speed == c.speed) continue;
    c.applied_speed = c.speed;
    // Each segment's x axis runs along the belt.
    for (size_t k = 0; k < belts_[r].size(); ++k) {
      const double curvature = c.curvature && k < c.curvature->size() ? (*c.curvature)[k] : 0.0;
      scene->SetSurfaceVelocity(scene->IdAt(belts_[r][k]), {c.speed, 0, 0},
                                {0, 0, c.speed * curvature});
    }
  }
}

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
    Advance(&p, dt);
    if (slots.empty()) continue;
    const Pose X_PC = p.curve->PoseAt(p.position);
    for (size_t k = 0; k < slots.size(); ++k)
      if (slots[k] != kNoSlot) scene->SetLocalPose(scene->IdAt(slots[k]), X_PC * p.offsets[k]);
  }
}

}  // namespace swarmsim::paths
