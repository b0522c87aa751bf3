// Copies and removals of robots at run time (paper §2.3; CoppeliaSim's
// sim.copyPasteObjects and sim.removeObjects on a model): what the scripts
// queued with sim.copyModel / sim.removeModel (lua_api_models.cc) is applied
// here, between the control and the actuate phase, in an order that does not
// depend on the thread count.
//
// A copy is Scene::DuplicateSubtree of the robot's model root, the loader's
// own path: every object's row through its type's copy hook, scripts (shared
// sources), custom data, and calculation objects through SceneListener (IK
// groups). The new robot gets the next robot index and the name
// <model>#<index>, the source's model parameters, its own random stream
// (seed, index) and its own Lua state, whose scripts' bodies and sysCall_init
// run here. A removal runs the robot's sysCall_cleanup, then
// Scene::RemoveSubtree (handles stale, listeners told), and drops its mail;
// its index is not reused and no other robot's index changes.
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/plugin_controllers.h"
#include "framework/world.h"

namespace swarmsim {

int World::live_robot_count() const {
  int live = 0;
  for (const ModelInstance& instance : scene_.instances()) live += instance.alive;
  return live;
}

void World::ApplyModelEdits() {
  // Robots in index order, then the scene's scripts (and the main script);
  // call order within each.
  std::vector<ModelEdit> edits;
  for (size_t r = 0; r < runtimes_.size(); ++r) {
    if (!(pending_[r] & kPendingModelEdits)) continue;
    pending_[r] &= ~kPendingModelEdits;
    // (Not get(): a robot marked pending without edits, as every robot is
    // after MarkAllPending, must not be given a list; each step's
    // PendingBits would then read it from the heap.)
    LazyVector<ModelEdit>& queued = runtimes_[r].model_edits;
    edits.insert(edits.end(), queued.begin(), queued.end());
    queued.clear();
  }
  edits.insert(edits.end(), scene_runtime_.model_edits.begin(), scene_runtime_.model_edits.end());
  scene_runtime_.model_edits.clear();
  if (edits.empty()) return;
  // Copies first, each from its source as the control phase left it (so a
  // robot copied and removed in the same step is copied, then removed).
  const int first_new = robot_count();
  std::vector<std::pair<int, int>> copies;  // (new robot, source robot)
  std::vector<uint64_t> charged;            // by copy: bytes taken at the call
  for (const ModelEdit& edit : edits) {
    if (edit.kind != ModelEdit::Kind::kCopy) continue;
    if (!scene_.IsValid(edit.root)) {
      run_script_memory_.Give(edit.charged);
      continue;
    }
    const int source = scene_.instance_of(edit.root);
    const ObjectId copy = CopyRobot(edit);
    copies.emplace_back(scene_.instance_of(copy), source);
    charged.push_back(edit.charged);
  }
  if (!copies.empty()) {
    EnsureRuntimes();
    for (size_t i = 0; i < copies.size(); ++i) {
      const auto [robot, source] = copies[i];
      runtimes_[robot].parameters = runtimes_[source].parameters;
      // Its objects, on its own account from now until it is removed (the
      // bytes sim.copyModel took from the run's, handed over).
      run_script_memory_.Give(charged[i]);
      robot_script_memory_[robot].Force(charged[i]);
      runtimes_[robot].lifetime_bytes += charged[i];
    }
    scripts_->StartInstances(first_new);
    // A copy runs its source's native controller, from a fresh init.
    if (controllers_) {
      for (const auto& [robot, source] : copies)
        if (const PluginControllerType* type = controllers_->type_of(source))
          controllers_->Assign(robot, type, controllers_->in_place_of_scripts(source));
      controllers_->Init(first_new);
    }
  }
  // Then removals (a robot removed twice goes once).
  for (const ModelEdit& edit : edits)
    if (edit.kind == ModelEdit::Kind::kRemove && scene_.IsValid(edit.root)) RemoveRobot(edit.root);
  // Then the objects scripts made (sim.createPath), robots in index order.
  bool added = false;
  for (const ModelEdit& edit : edits)
    if (edit.kind == ModelEdit::Kind::kAdd && edit.add) {
      edit.add(&scene_);
      added = true;
    }
  if (added) scene_.UpdateWorldPoses();
  // What the new robots' sysCall_init and the removed ones' sysCall_cleanup
  // printed, recorded or failed with, in robot order.
  for (const auto& [robot, source] : copies) pending_[robot] |= kPendingOutput;
  FlushRobotBuffers();
}

ObjectId World::CopyRobot(const ModelEdit& edit) {
  const ObjectId copy = scene_.DuplicateSubtree(edit.root, {});
  const int robot = scene_.instance_of(copy);
  scene_.set_name(copy, scene_.instance(robot).name);
  if (edit.has_pose) {
    // The source's root pose moved to (x, y) and turned about the world's z
    // axis to heading `yaw`; height, roll and pitch stay the source's.
    Pose X_WR = scene_.world_pose(copy);
    X_WR.q = Quat::FromYaw(edit.yaw - X_WR.q.Yaw()) * X_WR.q;
    X_WR.p.x = edit.x;
    X_WR.p.y = edit.y;
    scene_.SetWorldPose(copy, X_WR);
  }
  return copy;
}

void World::RemoveRobot(ObjectId root) {
  const int robot = scene_.instance_of(root);
  RobotRuntime& rt = runtimes_.at(robot);
  // Its scripts' sysCall_cleanup, while its objects still exist; a cleanup
  // error (under on_script_error: stop) ends the run after the robot is gone.
  std::string cleanup_error;
  if (controllers_) controllers_->Cleanup(robot);
  try {
    scripts_->StopInstance(robot);
  } catch (const std::exception& e) {
    cleanup_error = e.what();
  }
  scene_.RemoveSubtree(root);
  // What its cleanup queued (copies, removals) goes with it, and what the
  // copies took from the run's script memory; what it printed and recorded
  // is flushed by the caller.
  for (const ModelEdit& edit : rt.model_edits) run_script_memory_.Give(edit.charged);
  rt.model_edits.clear();
  pending_[robot] |= kPendingOutput;
  messaging_.ClearRobot(robot);
  // Its collections, and the charge for them and for the objects its
  // scripts made (gone with its subtree).
  rt.collections = {};
  robot_script_memory_[robot].Release(std::exchange(rt.lifetime_bytes, 0));
  if (!cleanup_error.empty()) {
    FlushBuffersAfterError();
    throw Error(cleanup_error);
  }
}

}  // namespace swarmsim
