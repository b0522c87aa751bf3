#include "modules/kinematics/ik_groups.h"

#include <algorithm>
#include <optional>
#include <string>
#include <unordered_map>

#include "framework/collections.h"
#include "framework/dependent_joints.h"
#include "framework/error.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/world.h"
#include "modules/collision/module.h"
#include "modules/kinematics/ik_model_section.h"
#include "modules/kinematics/ik_solver.h"

namespace swarmsim::kinematics {

// Its Lua area (lua_api_ik.cc).
void RegisterIkApi(lua_State* L);

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
  // Obstacle avoidance: per avoidance link of the problem, and per `avoid` entry.
  struct AvoidLink {
    uint32_t slot;                // the link object
    std::vector<uint32_t> parts;  // its rigid body's shapes (ascending)
    int entry;                    // in spec.avoid
  };
  std::vector<AvoidLink> avoid_links;
  std::vector<collision::Target> obstacles;
  std::vector<std::vector<uint32_t>> obstacle_slots;
  bool obstacles_resolved = false;
};

// The shapes of the rigid body of `link`: it and what hangs below it without
// crossing a joint, ascending.
std::vector<uint32_t> RigidBodyShapes(const Scene& scene, uint32_t link) {
  std::vector<uint32_t> subtree, out;
  scene.CollectSubtree(link, &subtree);
  for (uint32_t s : subtree) {
    bool rigid = true;
    for (uint32_t a = s; a != link && rigid; a = static_cast<uint32_t>(scene.parent_at(a)))
      rigid = scene.type_at(a) != ObjectType::kJoint;
    if (rigid && scene.type_at(s) == ObjectType::kShape) out.push_back(s);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// q_joint = offset + factor * q_root through a dependent joint's masters;
// returns the root (a joint that depends on none).
uint32_t RootMaster(const Scene& scene, uint32_t slot, double* factor, double* offset) {
  *factor = 1;
  *offset = 0;
  for (size_t hops = 0; hops <= scene.joints().size(); ++hops) {
    const JointData& j = scene.joints()[scene.row_at(slot)];
    const JointDependency* d = j.depends();
    if (d == nullptr) return slot;
    *offset += *factor * d->offset;
    *factor *= d->factor;
    slot = JointMasterSlot(scene, slot);
  }
  CheckJointDependency(scene, scene.IdAt(slot));  // a cycle: throws
  return slot;
}

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
    Build(&g, scene, false);  // reports a bad chain now, not at the first step
    groups_.push_back(std::move(g));
    by_instance_dirty_ = true;
    return static_cast<int>(groups_.size());
  }

  void Start(World* world) override { world_ = world; }

  void CheckReferences(const Scene& scene) override {
    for (Group& g : groups_)
      if (g.alive) Build(&g, scene, true);
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
    const IkStatus status = Solve(&g, scene, g.spec.avoid.empty() ? nullptr : Geometry(world_));
    if (g.spec.mode == IkMode::kDirect) RefreshPoses(g.instance, scene);
    return status;
  }

  void Actuate(World* world) override {
    if (groups_.empty()) return;
    world_ = world;
    Scene& scene = world->scene();
    RebuildByInstance(scene);
    const collision::Geometry* geometry = any_avoid_ ? Geometry(world) : nullptr;
    // Robots concurrently (each writes only its own joints), then the scene's groups.
    const bool independent = scene.InstancesAreIndependent();
    auto solve_robot = [&](int r) {
      for (int h : by_instance_[r]) {
        Group& g = groups_[h - 1];
        Solve(&g, &scene, geometry);
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
      Solve(&g, &scene, geometry);
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
      for (IkAvoidSpec& a : g.spec.avoid)
        for (ObjectId& link : a.links) link = remap(link);
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
      for (const IkAvoidSpec& a : g.spec.avoid)
        for (ObjectId link : a.links) remove |= gone(link);
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

  // The collision module's geometry as of this step (built every world).
  static const collision::Geometry* Geometry(World* world) {
    auto* module =
        world != nullptr
            ? dynamic_cast<collision::CollisionModule*>(world->find_module(collision::kModuleName))
            : nullptr;
    return module != nullptr ? &module->Fresh(*world) : nullptr;
  }

  // The problem from the scene; `obstacles`: resolve the avoid entries'
  // obstacle paths too (the world's objects exist).
  static void Build(Group* g, const Scene& scene, bool obstacles) {
    const std::string group = "IK group '" + g->spec.name + "'";
    IkProblem problem;
    g->base_slot.clear();
    g->fixed_target.clear();
    for (const IkTipSpec& t : g->spec.tips) {
      const int32_t base = BaseSlot(scene, t);
      const ObjectId base_id = base >= 0 ? scene.IdAt(static_cast<uint32_t>(base)) : ObjectId{};
      Chain tip_chain = Chain::FromScene(scene, base_id, t.tip);
      if (tip_chain.dof() == 0)
        throw Error(group + ": no joint between '" + scene.PathOf(base_id) + "' and the tip '" +
                    scene.PathOf(t.tip) + "'");
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
    // Avoidance links: chains from the first tip's base.
    g->avoid_links.clear();
    const int32_t base = g->base_slot.front();
    const ObjectId base_id = base >= 0 ? scene.IdAt(static_cast<uint32_t>(base)) : ObjectId{};
    for (size_t e = 0; e < g->spec.avoid.size(); ++e) {
      const IkAvoidSpec& a = g->spec.avoid[e];
      for (ObjectId link : a.links) {
        const uint32_t slot = scene.SlotOf(link, "IK avoid link");
        if (!IsAncestor(scene, base, slot))
          throw Error(a.where + ": " + group + ": the link '" + scene.PathOf(link) +
                      "' is not below the group's base '" + scene.PathOf(base_id) + "'");
        problem.AddAvoidLink(Chain::FromScene(scene, base_id, link), a.distance);
        g->avoid_links.push_back({slot, RigidBodyShapes(scene, slot), static_cast<int>(e)});
      }
    }
    const auto slots = problem.joint_slots();
    const auto column_of = [&](uint32_t slot) {
      auto it = std::find(slots.begin(), slots.end(), slot);
      return it == slots.end() ? -1 : static_cast<int>(it - slots.begin());
    };
    for (const auto& [joint, weight] : g->spec.weights) {
      const uint32_t slot = scene.SlotOf(joint, "IK weight joint");
      for (int c = 0; c < problem.dof(); ++c)
        if (slots[c] == slot) problem.set_weight(c, weight);
    }
    for (int c = 0; c < problem.dof(); ++c) {
      const JointData& j = scene.joints()[scene.row_at(slots[c])];
      // No dynamics backend drives a spherical joint to a target.
      if (problem.is_ball(c) && g->spec.mode == IkMode::kJointTargets)
        throw Error(group + ": the spherical joint '" + scene.PathOf(scene.IdAt(slots[c])) +
                    "' can only be solved in direct mode (mode: targets sets target "
                    "positions, and a spherical joint has none)");
      // A velocity-mode joint ignores the target position targets mode sets:
      // the group would report success with the arm where it was.
      if (g->spec.mode == IkMode::kJointTargets && !problem.is_ball_part(c) &&
          j.depends() == nullptr && j.mode() == JointMode::kVelocity)
        throw Error(group + ": the joint '" + scene.PathOf(scene.IdAt(slots[c])) +
                    "' is in velocity mode, which ignores the target positions mode: targets "
                    "sets (a URDF continuous joint is imported in velocity mode); use mode: "
                    "direct, or give the joint mode: position");
      // Dependent joints follow their master's column, or keep their value
      // if it is not an unknown of the group (whatever their weight).
      if (j.depends() == nullptr || problem.is_ball_part(c)) continue;
      double factor, offset;
      const int master = column_of(RootMaster(scene, slots[c], &factor, &offset));
      if (master >= 0 && !problem.is_ball_part(master))
        problem.SetDependent(c, master, factor, offset);
      else
        problem.set_weight(c, 0);
    }
    if (obstacles) ResolveObstacles(g, scene);
    g->problem = std::move(problem);
    g->built_version = scene.structure_version();
  }

  static void ResolveObstacles(Group* g, const Scene& scene) {
    // The first time a path that names nothing is an error; later it named
    // a robot removed since, and the obstacle is empty.
    const Missing missing = g->obstacles_resolved ? Missing::kNone : Missing::kError;
    g->obstacles.assign(g->spec.avoid.size(), {});
    g->obstacle_slots.assign(g->spec.avoid.size(), {});
    const ObjectId root = g->instance >= 0 ? scene.instance(g->instance).root : ObjectId{};
    for (size_t e = 0; e < g->spec.avoid.size(); ++e) {
      const IkAvoidSpec& a = g->spec.avoid[e];
      const std::string what = a.where + ": IK group '" + g->spec.name + "', avoid";
      const EntitySpec entity = ParseEntity(a.obstacle);
      if (entity.kind == EntitySpec::kEverythingElse)
        throw Error(what +
                    ": 'everything_else' would include the arm itself: name a "
                    "collection, an object or 'environment'");
      if (entity.kind == EntitySpec::kPath)
        g->obstacle_slots[e] = EntitySlots(scene, entity.path, root, what, missing);
      g->obstacles[e].kind = entity.kind;
    }
    g->obstacles_resolved = true;
  }

  // Each avoidance link's distance to its obstacle now (within 3 clearances).
  static void MeasureClearances(Group* g, const Scene& scene, const collision::Geometry& geometry) {
    IkProblem& problem = *g->problem;
    for (size_t i = 0; i < g->avoid_links.size(); ++i) {
      const Group::AvoidLink& link = g->avoid_links[i];
      const IkAvoidSpec& a = g->spec.avoid[link.entry];
      const std::vector<uint32_t> parts = geometry.ShapesOf(scene, link.parts);
      const std::vector<uint32_t> obstacle =
          geometry.ShapesOf(scene, g->obstacle_slots[link.entry]);
      collision::Target target = g->obstacles[link.entry];
      target.slots = obstacle;
      IkClearance reading;
      reading.X_WLink = scene.world_pose_at(link.slot);
      if (!parts.empty() && (target.kind != EntitySpec::kPath || !obstacle.empty())) {
        const collision::DistanceAnswer d = geometry.Distance(
            parts, target, 3 * a.distance, collision::kNoSlot, collision::kNoSlot);
        reading.near = d.found;
        reading.distance = d.distance;
        reading.p_WL = d.p1;
        // Away from the obstacle; touching: from its point to the link's frame.
        Vec3 n = d.p1 - d.p2;
        if (!(d.distance > 1e-9) || n.Norm() < 1e-12) n = reading.X_WLink.p - d.p2;
        reading.n_W = n.Norm() > 1e-12 ? n * (1 / n.Norm()) : Vec3{0, 0, 1};
      }
      problem.set_clearance(static_cast<int>(i), reading);
    }
  }

  static IkStatus Solve(Group* g, Scene* scene, const collision::Geometry* geometry) {
    if (!g->problem || g->built_version != scene->structure_version()) Build(g, *scene, true);
    if (!g->obstacles_resolved) ResolveObstacles(g, *scene);
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
    const int32_t b = g->base_slot.front();
    for (int i = 0; i < problem.avoid_link_count(); ++i)
      problem.set_avoid_base_pose(i,
                                  b >= 0 ? scene->ChildFrameAt(static_cast<uint32_t>(b)) : Pose{});
    if (geometry != nullptr) MeasureClearances(g, *scene, *geometry);
    // Joint-target mode solves from the last targets (the kinematic model the
    // dynamics tracks), direct mode from the positions; frozen joints keep theirs.
    const bool targets = g->spec.mode == IkMode::kJointTargets;
    const auto slots = problem.joint_slots();
    std::vector<double> q(slots.size(), 0.0);
    std::vector<Quat> ball(slots.size());
    for (size_t c = 0; c < slots.size(); ++c) {
      const JointData& j = scene->joints()[scene->row_at(slots[c])];
      problem.set_frozen(static_cast<int>(c), j.ik_frozen);
      if (problem.is_ball_part(static_cast<int>(c)))
        ball[c] = j.ball;
      else
        q[c] = targets ? j.target_position : j.position;
    }
    IkSettings settings;
    settings.damping = g->spec.damping;
    settings.max_iterations = g->spec.max_iterations;
    settings.position_tolerance = g->spec.position_tolerance;
    settings.orientation_tolerance = g->spec.orientation_tolerance;
    settings.max_step = g->spec.max_step;
    settings.apply_only_when_solved = g->spec.conditional;
    const IkResult result = problem.Solve(settings, &q, &ball);
    if (result.solved || !g->spec.conditional) {
      for (size_t c = 0; c < slots.size(); ++c) {
        JointData& j = scene->joints()[scene->row_at(slots[c])];
        if (problem.is_ball(static_cast<int>(c))) j.ball = ball[c];
        if (problem.is_ball_part(static_cast<int>(c))) continue;
        j.target_position = q[c];
        if (!targets) j.position = q[c];
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
    any_avoid_ = std::any_of(groups_.begin(), groups_.end(),
                             [](const Group& g) { return g.alive && !g.spec.avoid.empty(); });
  }

  std::vector<Group> groups_;
  std::vector<std::vector<int>> by_instance_;  // automatic group handles per robot
  std::vector<int> scene_groups_;
  bool by_instance_dirty_ = true;
  bool any_avoid_ = false;  // a live group avoids obstacles
  World* world_ = nullptr;  // since the first actuate phase (sim.handleIkGroup's geometry)
};

}  // namespace

IkGroups& IkGroupsOf(World* world) {
  auto* groups = dynamic_cast<IkGroups*>(world->module(kIkModuleName));
  if (groups == nullptr) throw Error("the 'ik' calculation module is not an IK module");
  return *groups;
}

IkGroups* FindIkGroups(const World& world) {
  return dynamic_cast<IkGroups*>(world.find_module(kIkModuleName));
}

void Register(ModuleRegistry* registry) {
  registry->RegisterModule(
      {{"calculation", kIkModuleName, "1.0",
        "IK groups: damped least squares, several tips, closed chains, per robot in parallel"},
       PhaseBit(Phase::kActuate),
       100,
       /*every_world=*/false,
       [](World*, const void*) -> std::unique_ptr<Module> {
         return std::make_unique<IkGroupsImpl>();
       },
       RegisterIkApi});
  registry->RegisterModelSection(IkGroupsSection());  // `ik_groups:` of model files
}

}  // namespace swarmsim::kinematics
