#include "modules/kinematics/ik_groups.h"

#include <algorithm>
#include <optional>
#include <string>
#include <unordered_map>

#include "framework/error.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "modules/kinematics/ik_solver.h"

namespace swarmsim::kinematics {
namespace {

// Robots per task: a leg's solve is a few microseconds.
constexpr int64_t kRobotGrain = 4;

struct Group {
  IkGroupSpec spec;
  int instance = -1;
  bool alive = true;
  IkStatus last = IkStatus::kNotPerformed;
  // Built from the scene on first use and after structural changes.
  uint64_t built_version = ~uint64_t{0};
  std::optional<IkProblem> problem;
  std::vector<int32_t> base_slot;     // per tip, -1: the world
  std::vector<int32_t> fixed_target;  // per tip: target slot read each solve, -1: closed chain
};

bool IsAncestor(const Scene& scene, int32_t ancestor, uint32_t slot) {
  if (ancestor < 0) return true;
  for (int32_t s = static_cast<int32_t>(slot); s >= 0;
       s = scene.parent_at(static_cast<uint32_t>(s)))
    if (s == ancestor) return true;
  return false;
}

// The tip's base: as given, else its model's root, else the world.
int32_t BaseSlot(const Scene& scene, const IkTipSpec& tip) {
  if (!tip.base.IsNull()) return static_cast<int32_t>(scene.SlotOf(tip.base, "IK base"));
  const int instance = scene.instance_of(tip.tip);
  if (instance < 0) return -1;
  return static_cast<int32_t>(scene.instance(instance).root.index());
}

class IkGroupsImpl final : public IkGroups {
 public:
  int AddGroup(const Scene& scene, IkGroupSpec spec) override {
    if (spec.tips.empty()) throw Error("IK group '" + spec.name + "' has no tips");
    for (const IkTipSpec& t : spec.tips) {
      scene.SlotOf(t.tip, "IK tip");
      scene.SlotOf(t.target, "IK target");
    }
    Group g;
    g.instance = scene.instance_of(spec.tips.front().tip);
    g.spec = std::move(spec);
    Build(&g, scene);  // reports a bad chain now, not at the first step
    groups_.push_back(std::move(g));
    by_instance_dirty_ = true;
    return static_cast<int>(groups_.size());
  }

  int FindGroup(std::string_view name, int instance) const override {
    for (size_t i = 0; i < groups_.size(); ++i)
      if (groups_[i].alive && groups_[i].instance == instance && groups_[i].spec.name == name)
        return static_cast<int>(i) + 1;
    return 0;
  }

  bool IsLive(int handle) const override {
    return handle >= 1 && handle <= static_cast<int>(groups_.size()) && groups_[handle - 1].alive;
  }
  int instance_of(int handle) const override { return At(handle).instance; }
  const IkGroupSpec& spec(int handle) const override { return At(handle).spec; }
  IkStatus last_status(int handle) const override { return At(handle).last; }
  int live_group_count() const override {
    return static_cast<int>(
        std::count_if(groups_.begin(), groups_.end(), [](const Group& g) { return g.alive; }));
  }

  IkStatus Handle(int handle, Scene* scene) override {
    Group& g = At(handle);
    const IkStatus status = Solve(&g, scene);
    if (g.spec.mode == IkMode::kDirect) RefreshPoses(g.instance, scene);
    return status;
  }

  void Actuate(World* world) override {
    if (groups_.empty()) return;
    Scene& scene = world->scene();
    RebuildByInstance(scene);
    // Robots concurrently (each writes only its own joints), then the scene's groups.
    const bool independent = scene.InstancesAreIndependent();
    auto solve_robot = [&](int r) {
      for (int h : by_instance_[r]) {
        Group& g = groups_[h - 1];
        Solve(&g, &scene);
        // Direct mode: later groups of the robot see the new poses.
        if (g.spec.mode != IkMode::kDirect) continue;
        if (independent)
          scene.UpdateWorldPoses(r);
        else
          scene.UpdateWorldPoses();
      }
    };
    const int64_t n = static_cast<int64_t>(by_instance_.size());
    if (independent) {
      world->scheduler().ParallelFor(0, n, kRobotGrain, [&](int64_t begin, int64_t end) {
        for (int64_t r = begin; r < end; ++r) solve_robot(static_cast<int>(r));
      });
    } else {
      for (int64_t r = 0; r < n; ++r) solve_robot(static_cast<int>(r));
    }
    for (int h : scene_groups_) {
      Group& g = groups_[h - 1];
      Solve(&g, &scene);
      if (g.spec.mode == IkMode::kDirect) scene.UpdateWorldPoses();
    }
  }

  void HashState(StateHasher* hasher) const override {
    for (const Group& g : groups_) {
      hasher->AddValue(g.alive);
      hasher->AddValue(g.last);
    }
  }

  // --- Following the model ------------------------------------------------------------
  void OnSubtreeDuplicated(const Scene& scene, std::span<const uint32_t> sources,
                           std::span<const uint32_t> copies) override {
    std::unordered_map<uint32_t, uint32_t> copy_of;
    for (size_t i = 0; i < sources.size(); ++i) copy_of[sources[i]] = copies[i];
    auto remap = [&](ObjectId id) {
      if (id.IsNull()) return id;
      auto it = copy_of.find(id.index());
      return it == copy_of.end() ? id : scene.IdAt(it->second);
    };
    // A group whose tips were all copied is copied, references remapped
    // (one outside the copied subtree, such as a world target, is kept).
    const size_t existing = groups_.size();
    for (size_t i = 0; i < existing; ++i) {
      if (!groups_[i].alive) continue;
      bool all_tips = true;
      for (const IkTipSpec& t : groups_[i].spec.tips) all_tips &= copy_of.count(t.tip.index()) > 0;
      if (!all_tips) continue;
      Group g;
      g.spec = groups_[i].spec;
      for (IkTipSpec& t : g.spec.tips) {
        t.tip = remap(t.tip);
        t.target = remap(t.target);
        t.base = remap(t.base);
      }
      for (auto& [joint, weight] : g.spec.weights) joint = remap(joint);
      g.instance = scene.instance_of(g.spec.tips.front().tip);
      groups_.push_back(std::move(g));
    }
    if (groups_.size() != existing) by_instance_dirty_ = true;
  }

  void OnSubtreeRemoved(const Scene& scene, std::span<const uint32_t> slots) override {
    // A group that refers to a removed object is removed.
    std::vector<uint8_t> doomed(scene.slot_count(), 0);
    for (uint32_t s : slots) doomed[s] = 1;
    auto gone = [&](ObjectId id) { return !id.IsNull() && doomed[id.index()]; };
    for (Group& g : groups_) {
      if (!g.alive) continue;
      bool remove = false;
      for (const IkTipSpec& t : g.spec.tips)
        remove |= gone(t.tip) || gone(t.target) || gone(t.base);
      for (const auto& [joint, weight] : g.spec.weights) remove |= gone(joint);
      if (remove) {
        g.alive = false;
        g.problem.reset();
        by_instance_dirty_ = true;
      }
    }
  }

 private:
  Group& At(int handle) {
    if (!IsLive(handle))
      throw Error("no IK group with handle " + std::to_string(handle) +
                  " (it was removed with its model, or never existed)");
    return groups_[handle - 1];
  }
  const Group& At(int handle) const { return const_cast<IkGroupsImpl*>(this)->At(handle); }

  static void Build(Group* g, const Scene& scene) {
    IkProblem problem;
    g->base_slot.clear();
    g->fixed_target.clear();
    for (const IkTipSpec& t : g->spec.tips) {
      const int32_t base = BaseSlot(scene, t);
      const ObjectId base_id = base >= 0 ? scene.IdAt(static_cast<uint32_t>(base)) : ObjectId{};
      Chain tip_chain = Chain::FromScene(scene, base_id, t.tip);
      if (tip_chain.dof() == 0)
        throw Error("IK group '" + g->spec.name + "': no joint between '" + scene.PathOf(base_id) +
                    "' and the tip '" + scene.PathOf(t.tip) + "'");
      const uint32_t target_slot = scene.SlotOf(t.target, "IK target");
      Chain target_chain;
      const bool below_base = base >= 0 && IsAncestor(scene, base, target_slot);
      if (below_base) target_chain = Chain::FromScene(scene, base_id, t.target);
      if (below_base && target_chain.dof() > 0) {
        problem.AddClosedElement(std::move(tip_chain), std::move(target_chain), t.constraints);
        g->fixed_target.push_back(-1);
      } else {
        problem.AddElement(std::move(tip_chain), scene.world_pose_at(target_slot), t.constraints);
        g->fixed_target.push_back(static_cast<int32_t>(target_slot));
      }
      g->base_slot.push_back(base);
    }
    for (const auto& [joint, weight] : g->spec.weights) {
      const uint32_t slot = scene.SlotOf(joint, "IK weight joint");
      const auto slots = problem.joint_slots();
      auto it = std::find(slots.begin(), slots.end(), slot);
      if (it != slots.end()) problem.set_weight(static_cast<int>(it - slots.begin()), weight);
    }
    g->problem = std::move(problem);
    g->built_version = scene.structure_version();
  }

  static IkStatus Solve(Group* g, Scene* scene) {
    if (!g->problem || g->built_version != scene->structure_version()) Build(g, *scene);
    IkProblem& problem = *g->problem;
    // Moving bases and targets as they are now.
    for (size_t e = 0; e < g->base_slot.size(); ++e) {
      const int32_t b = g->base_slot[e];
      problem.set_base_pose(static_cast<int>(e),
                            b >= 0 ? scene->ChildFrameAt(static_cast<uint32_t>(b)) : Pose{});
      if (g->fixed_target[e] >= 0)
        problem.set_target(static_cast<int>(e),
                           scene->world_pose_at(static_cast<uint32_t>(g->fixed_target[e])));
    }
    // Joint-target mode solves from the last targets (the kinematic model the
    // dynamics tracks), direct mode from the positions.
    const bool targets = g->spec.mode == IkMode::kJointTargets;
    std::vector<double> q;
    q.reserve(problem.dof());
    for (uint32_t s : problem.joint_slots()) {
      const JointData& j = scene->joints()[scene->row_at(s)];
      q.push_back(targets ? j.target_position : j.position);
    }
    IkSettings settings;
    settings.damping = g->spec.damping;
    settings.max_iterations = g->spec.max_iterations;
    settings.position_tolerance = g->spec.position_tolerance;
    settings.orientation_tolerance = g->spec.orientation_tolerance;
    settings.max_step = g->spec.max_step;
    settings.apply_only_when_solved = g->spec.conditional;
    const IkResult result = problem.Solve(settings, &q);
    if (result.solved || !g->spec.conditional) {
      const auto slots = problem.joint_slots();
      for (size_t i = 0; i < slots.size(); ++i) {
        JointData& j = scene->joints()[scene->row_at(slots[i])];
        j.target_position = q[i];
        if (!targets) j.position = q[i];
      }
    }
    g->last = result.solved ? IkStatus::kSolved : IkStatus::kFailed;
    return g->last;
  }

  static void RefreshPoses(int instance, Scene* scene) {
    if (instance >= 0 && scene->InstancesAreIndependent())
      scene->UpdateWorldPoses(instance);
    else
      scene->UpdateWorldPoses();
  }

  void RebuildByInstance(const Scene& scene) {
    if (!by_instance_dirty_ && by_instance_.size() == scene.instances().size()) return;
    by_instance_.assign(scene.instances().size(), {});
    scene_groups_.clear();
    for (size_t i = 0; i < groups_.size(); ++i) {
      const Group& g = groups_[i];
      if (!g.alive || !g.spec.automatic) continue;
      if (g.instance >= 0)
        by_instance_[g.instance].push_back(static_cast<int>(i) + 1);
      else
        scene_groups_.push_back(static_cast<int>(i) + 1);
    }
    by_instance_dirty_ = false;
  }

  std::vector<Group> groups_;
  std::vector<std::vector<int>> by_instance_;  // automatic group handles per robot
  std::vector<int> scene_groups_;
  bool by_instance_dirty_ = true;
};

}  // namespace

ModuleInfo IkModuleInfo() {
  return {"calculation", kIkModuleName, "1.0",
          "IK groups: damped least squares, several tips, closed chains, per robot in parallel"};
}

std::unique_ptr<IkGroups> MakeIkGroups() { return std::make_unique<IkGroupsImpl>(); }

}  // namespace swarmsim::kinematics
