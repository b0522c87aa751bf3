// The scene: a tree of objects in world-owned storage.
//
// Objects are referred to by ObjectId {index1, generation}. Per-object hot
// data (poses, velocities, parent links) lives in dense arrays indexed by slot;
// type-specific data lives in one dense table per object type, each row
// pointing back at its object. What a type's rows are and how they are
// copied, scaled and hashed is its descriptor's (framework/object_type.h):
// Scene holds a table per registered type and calls those hooks; it has no
// code of its own per type. Names, scripts and model bookkeeping are cold
// arrays.
//
// A model is a subtree whose root is marked as a model. Each top-level model
// copy is a *model instance* (a robot): the unit of parallelism and of random
// streams. DuplicateSubtree copies rows, not assets (script sources are shared).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "framework/environment.h"
#include "framework/handle.h"
#include "framework/math.h"
#include "framework/mesh.h"
#include "framework/name_pool.h"
#include "framework/object_rows.h"
#include "framework/sensor_noise.h"
#include "framework/shared_settings.h"

namespace swarmsim {

class Prefault;
class ScriptMemory;
class StateHasher;
class StateReader;
class StateWriter;
class TaskScheduler;
struct ObjectTypeDescriptor;

// The name of a built-in type ("joint"); Scene::type_name names registered
// ones too.
const char* ToString(ObjectType type);

enum class ShapeKind : uint8_t { kBox, kCylinder, kSphere, kCapsule, kMesh };
const char* ToString(ShapeKind kind);

// Geometry is centred on the shape's frame; a cylinder's axis is its z axis.
// A capsule is a cylinder with hemispherical caps along z; its height is the
// total length, caps included (>= 2 radius), so its bounding cylinder has the
// same size (modules that lack exact capsule code use that).
// A mesh is a shared, immutable triangle mesh (framework/mesh.h) in the
// shape's frame; its `size` holds the full extents of the smallest box
// centred on the frame that contains it, so box-based fallbacks stay
// conservative.
struct ShapeData {
  ShapeKind kind = ShapeKind::kBox;
  Vec3 size{0.1, 0.1, 0.1};  // box: full extents (x, y, z) m; cylinder, capsule: (radius, -,
                             // height); sphere: (radius, -, -)
  bool dynamic = false;      // simulated by the dynamics backend, else static or kinematic
  double mass = 1.0;         // kg, dynamic shapes only
  // Inertia about the centre of mass in the shape's axes, kg m^2: (ixx, iyy,
  // izz, ixy, ixz, iyz); all zero: the dynamics backend derives it from the geometry.
  std::array<double, 6> inertia{};
  // m, in the shape's frame: where the dynamics backend puts the mass (ode:
  // a URDF body's combined centre of mass); zero: the shape's origin.
  Vec3 center_of_mass;
  // false: no contacts in the dynamics backends (a URDF visual, a body's
  // mass carrier); sensors still see it.
  bool collidable = true;
  // false: not drawn (viewer, recording, snapshots, video, vision sensors);
  // it still collides and proximity sensors still detect it (a URDF link's
  // collision geometry when the link has visuals).
  bool visible = true;
  double friction = 0.7;  // Coulomb coefficient
  double restitution = 0.0;
  Vec3 color{0.7, 0.7, 0.7};  // RGB in [0, 1]
  // kMesh: drawn in the mesh file's material colours, if it has any, until
  // a colour is given (the `color` key, sim.setShapeColor).
  bool mesh_colors = true;
  std::shared_ptr<const TriangleMesh> mesh;  // kMesh: the asset (shared by copies), else null
  // A moving surface (a conveyor belt's, modules/paths): its surface slides
  // relative to the shape, a point p of it (in the shape's frame) at
  // surface_velocity + surface_angular_velocity x p (m/s, rad/s, in the
  // shape's frame: a belt's segment on a bend turns about the bend's
  // centre). The dynamics backends make contacts carry what touches it
  // along. Set them through Scene::SetSurfaceVelocity.
  Vec3 surface_velocity;
  Vec3 surface_angular_velocity;
  bool HasMovingSurface() const {
    return !(surface_velocity == Vec3{}) || !(surface_angular_velocity == Vec3{});
  }

  // Radius of the shape's footprint circle in its xy plane (for broad phases).
  double BoundingRadius() const;
};

// Whether (ixx, iyy, izz, ixy, ixz, iyz) is a rigid body's inertia: finite,
// positive definite, each principal moment at most the sum of the others.
bool InertiaIsValid(const std::array<double, 6>& inertia);

enum class JointType : uint8_t { kRevolute, kPrismatic, kSpherical, kFixed, kScrew };
// kForce: the joint applies target_force (N or N m) and moves only if a
// dynamics backend simulates it.
enum class JointMode : uint8_t { kPassive, kVelocity, kPosition, kForce };
const char* ToString(JointType type);
const char* ToString(JointMode mode);

// A dependent joint (V-REP's dependent mode, URDF's mimic): its position is
// offset + factor * (the master's position), set every step after the
// master moved (framework/dependent_joints.h). `master` is a path as world
// files write it ("/robot/j", ":/j", "./j"), resolved from the joint; shared
// by copies, so a model copy's joint follows its own copy's master.
struct JointDependency {
  std::string master;
  double factor = 1;
  double offset = 0;
  std::string where;  // file:line:column of `master`, for errors
};

// A joint's settings: constant while it runs, shared by every copy made
// from one model entry (framework/shared_settings.h; Edit() is copy on
// write: a scale, or a copy's own `instances:` values, give it its own).
struct JointSettings {
  JointType type = JointType::kRevolute;
  JointMode mode = JointMode::kVelocity;
  double max_force = 10;            // N or N m
  double max_velocity = 10;         // rad/s or m/s, position mode
  double damping = 0;               // N m s/rad or N s/m: viscous -damping * velocity (ode)
  double min_position = -INFINITY;  // limits, rad or m (infinite: unlimited)
  double max_position = INFINITY;
  double pitch = 0;  // screw joints: m per rad, finite and nonzero
  // ode: the limits' (stops') ERP, 0..1, and CFM, 0..1; negative: the
  // world's (simulation.ode.limit_erp, limit_cfm).
  double limit_erp = -1;
  double limit_cfm = -1;
  std::shared_ptr<const JointDependency> depends;  // null: an independent joint
  // Actuation noise, velocity mode (a wheel's motor): the speed driven is
  // target * (1 - slip) * (1 + N(0, velocity_noise_factor)) + noise, and
  // zero in a step the motor fails (framework/sensor_noise.h; keys
  // velocity_noise, velocity_noise_uniform, velocity_noise_factor,
  // velocity_failure_probability, slip). World::Actuate draws it.
  NoiseSettings velocity_noise;
  double velocity_noise_factor = 0;
  double slip = 0;  // 0..1: the fraction of the commanded speed lost
  bool drive_noisy() const { return velocity_noise.any() || velocity_noise_factor > 0 || slip > 0; }
};

// A joint moves its children along/about its own z axis (V-REP's convention):
// X_W(child) = X_WJ * Motion(position) * X_J(child). A spherical joint turns
// them by `ball` (position and velocity unused); a fixed joint does not move.
// A screw joint turns them by `position` (rad) about z and moves them
// pitch * position (m) along z.
//
// A row is its shared settings and its state (96 bytes): what the actuate
// and physics phases, scripts and IK write. The state hash reads the state.
struct JointData {
  Shared<JointSettings> settings;  // read: settings->max_force; write: settings.Edit()
  double position = 0;             // rad or m
  double velocity = 0;             // rad/s or m/s
  double target_velocity = 0;      // velocity mode (scripts set it every step)
  // The speed driven this step when the joint has actuation noise (set by
  // World::Actuate; DriveVelocity() reads it): derived from the target and
  // the step's draws, so not hashed.
  double drive_velocity = 0;
  double target_position = 0;  // position mode
  double target_force = 0;     // N or N m, force mode
  Quat ball;                   // spherical joints: rotation of the children
  // Set by a dynamics backend that integrates this joint's position and
  // velocity itself; World::Actuate then leaves them alone.
  bool simulated = false;
  // IK mode (V-REP's joint IK mode): a frozen joint keeps its value while
  // IK groups solve (the `ik` key, sim.setJointIkMode, which scripts may
  // switch at any step: state, hashed when set).
  bool ik_frozen = false;

  JointType type() const { return settings->type; }
  JointMode mode() const { return settings->mode; }
  const JointDependency* depends() const { return settings->depends.get(); }  // null: independent
  // What a velocity-mode motor drives: the target, or with actuation noise
  // this step's noisy speed. The dynamics backends read this.
  double DriveVelocity() const {
    return settings->drive_noisy() ? drive_velocity : target_velocity;
  }
  Pose Motion() const;  // transform produced by `position` about/along z
  // sim.setJointPosition on a joint nothing simulates: it jumps to q and
  // stays (a position-mode joint's target becomes q, its velocity 0).
  void JumpTo(double q);
};

// A script attached to an object. The source is shared by all copies.
struct ScriptSource {
  std::string path;  // file the code came from (for messages)
  std::string code;
};
struct ScriptAttachment {
  std::shared_ptr<const ScriptSource> source;
  bool enabled = true;
  // Runs only when an ancestor's script calls sim.handleChildScript(handle, ...).
  bool explicit_handling = false;
};

// A top-level model copy: one robot.
struct ModelInstance {
  std::string name;        // e.g. "footbot#12"
  std::string model_name;  // e.g. "footbot"
  ObjectId root;
  bool alive = true;
  std::vector<uint32_t> objects;  // slots of the instance's objects, hierarchy (DFS pre-)order
};

class Scene;

// Calculation objects that refer to scene objects (IK groups, ...) follow
// them through duplication and removal (Scene::AddListener).
class SceneListener {
 public:
  virtual ~SceneListener() = default;
  // sources[i] was copied to copies[i] (slots, hierarchy order); the copy
  // is complete (a copied robot is already an instance).
  virtual void OnSubtreeDuplicated(const Scene& scene, std::span<const uint32_t> sources,
                                   std::span<const uint32_t> copies) = 0;
  // `slots` are about to be freed.
  virtual void OnSubtreeRemoved(const Scene& scene, std::span<const uint32_t> slots) = 0;
};

class Scene {
 public:
  Scene();
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // --- Object types ---------------------------------------------------------------
  // The built-in types are there from the start; a registered type (a
  // module's or a plugin's) gets the next ObjectType value. Throws
  // swarmsim::Error for a name already taken. The descriptor must outlive
  // the scene.
  ObjectType RegisterType(const ObjectTypeDescriptor& type);
  const ObjectTypeDescriptor& type_descriptor(ObjectType type) const {
    return *types_[static_cast<size_t>(type)];
  }
  // Every type, in ObjectType order.
  std::span<const ObjectTypeDescriptor* const> types() const { return types_; }
  // Every type in listing order (ListingOrder, object_type.h): the order
  // the state hash adds their rows in.
  std::span<const ObjectType> listing_order() const { return listing_order_; }
  // The type named `name`; false if there is none.
  bool FindType(std::string_view name, ObjectType* type) const;
  const char* type_name(ObjectType type) const {
    const size_t t = static_cast<size_t>(type);
    return t < type_names_.size() ? type_names_[t] : "?";
  }
  // The rows of a type (null for a type without rows, such as dummy).
  RowTable* rows(ObjectType type) { return tables_[static_cast<size_t>(type)].get(); }
  const RowTable* rows(ObjectType type) const { return tables_[static_cast<size_t>(type)].get(); }
  // The rows of a type as their C++ type: how a module reads its own
  // types' rows (`scene.rows<LedRow>(led_type)`, the type from FindType or
  // RegisterType). `Row` must be the type's row type.
  template <typename Row>
  Rows<Row>& rows(ObjectType type) {
    return Table<Row>(type);
  }
  template <typename Row>
  const Rows<Row>& rows(ObjectType type) const {
    return Table<Row>(type);
  }
  // The row of object `id`, which must be of `type` (`Row` its row type):
  // how a module's Lua area reads one object's row. Throws swarmsim::Error
  // for a stale handle ("no <what> ...") or an object of another type.
  template <typename Row>
  Row& row(ObjectType type, ObjectId id, std::string_view what) {
    return Table<Row>(type).rows[row_[SlotOfType(id, type, what)]];
  }
  template <typename Row>
  const Row& row(ObjectType type, ObjectId id, std::string_view what) const {
    return Table<Row>(type).rows[row_[SlotOfType(id, type, what)]];
  }
  // The slot of `id`, checked as row() checks it.
  uint32_t SlotOfType(ObjectId id, ObjectType type, std::string_view what) const;

  // --- Creation and deletion --------------------------------------------------
  // `parent` may be null (a root). X_PO is the pose of the new object in its
  // parent. `row` points at a row of the type's row type to copy, or is null
  // for the type's default row.
  ObjectId AddObject(ObjectType type, std::string name, ObjectId parent, const Pose& X_PO,
                     const void* row);
  ObjectId AddDummy(std::string name, ObjectId parent, const Pose& X_PO);
  ObjectId AddShape(std::string name, ObjectId parent, const Pose& X_PO, const ShapeData& shape);
  ObjectId AddJoint(std::string name, ObjectId parent, const Pose& X_PO, const JointData& joint);
  // Removes an object and all its descendants (their handles become stale).
  void RemoveSubtree(ObjectId root);
  // Copies a subtree under `new_parent` (null: a new root), with its scripts,
  // model marks and internal references (dummy links) remapped to the copy.
  // Returns the copy's root. With `X_PO`, the copy's root is placed there
  // (in its new parent's frame) as part of the copy: the same as
  // SetWorldPose after it for a new root, without computing the poses twice.
  ObjectId DuplicateSubtree(ObjectId root, ObjectId new_parent, const Pose* X_PO = nullptr);
  // X_WR.size() copies of the subtree at `root`, each a new root placed at
  // X_WR[i] (world frame): the same slots, rows, names, scripts, robots and
  // listener calls as DuplicateSubtree(root, {}, &X_WR[i]) for each i in
  // turn, with the copies' columns and rows (types without a copy rule)
  // written on `scheduler`'s threads. Copies one at a time where the
  // sources hold what only that path handles (custom data, dummy links) or
  // freed slots would be reused. Returns the copies' roots, in order.
  std::vector<ObjectId> DuplicateSubtrees(ObjectId root, std::span<const Pose> X_WR,
                                          TaskScheduler& scheduler);
  void SetParent(ObjectId id, ObjectId new_parent, bool keep_world_pose);
  // Listeners are told of duplications and removals; not owned.
  void AddListener(SceneListener* listener) { listeners_.push_back(listener); }
  // Reserves room for `copies` more duplicates of the subtree at `root`, so
  // placing ten thousand robots grows no array (and peak memory stays at
  // what the robots use). With `prefault`, the room reserved is added to it,
  // for the caller to populate on every thread before copying
  // (framework/prefault.h).
  void ReserveForCopies(ObjectId root, size_t copies, Prefault* prefault = nullptr);

  // --- Validity ---------------------------------------------------------------
  bool IsValid(ObjectId id) const {  // inline: every sim.* call checks its handles
    const uint32_t i = id.index();
    return !id.IsNull() && i < generation_.size() && alive_[i] && generation_[i] == id.generation;
  }
  // Slot of a valid handle; throws swarmsim::Error naming `what` for a null,
  // stale or out-of-range one.
  uint32_t SlotOf(ObjectId id, std::string_view what = "object") const;
  ObjectId IdAt(uint32_t slot) const { return {slot + 1, generation_[slot]}; }
  uint32_t slot_count() const { return static_cast<uint32_t>(generation_.size()); }
  bool alive_at(uint32_t slot) const { return alive_[slot] != 0; }
  size_t object_count() const { return object_count_; }

  // --- Tree -------------------------------------------------------------------
  ObjectId parent(ObjectId id) const;
  std::vector<ObjectId> children(ObjectId id) const;
  int32_t parent_at(uint32_t slot) const { return parent_[slot]; }
  // Is `ancestor` above `slot` in the tree (its parent, or its parent's, ...)?
  bool IsAbove(uint32_t ancestor, uint32_t slot) const {
    for (int32_t s = parent_[slot]; s >= 0; s = parent_[static_cast<uint32_t>(s)])
      if (static_cast<uint32_t>(s) == ancestor) return true;
    return false;
  }
  const std::string& name(ObjectId id) const { return names_[name_[SlotOf(id)]]; }
  const std::string& name_at(uint32_t slot) const { return names_[name_[slot]]; }
  void set_name(ObjectId id, std::string name);
  ObjectType type(ObjectId id) const { return type_[SlotOf(id)]; }
  ObjectType type_at(uint32_t slot) const { return type_[slot]; }
  // Path lookup, CoppeliaSim style. Absolute: "/robot/leftMotor"; relative to
  // `from`: "./leftMotor" (a descendant of `from`), ":/sensor" (a descendant
  // of `from`'s model root). "name[k]" picks the k-th (0-based) match of a
  // repeated name in hierarchy order. Returns null when nothing matches.
  ObjectId FindObject(std::string_view path, ObjectId from = {}) const;
  // Appends the slots of `slot`'s subtree (itself first), hierarchy order.
  void CollectSubtree(uint32_t slot, std::vector<uint32_t>* out) const;
  // Why FindObject(path, from) found nothing, to end an error message: at
  // the first element that matched nothing, "; did you mean '<path with the
  // nearest name>'?", "; there are 3 objects named 'prox' there:
  // prox[0]..prox[2]" or "; the names there: a, b"; "" if there is nothing
  // to say. Walks the tree again: for error paths only.
  std::string ExplainMissingPath(std::string_view path, ObjectId from = {}) const;
  // Slash-separated path from the root, e.g. "/footbot#3/leftMotor".
  std::string PathOf(ObjectId id) const;

  // --- Poses and velocities (hot, by slot) ------------------------------------
  const Pose& local_pose_at(uint32_t slot) const { return X_PO_[slot]; }
  const Pose& world_pose_at(uint32_t slot) const { return X_WO_[slot]; }
  // Velocities are kept for shapes, the bodies dynamics backends simulate;
  // every other object reads zero.
  const Vec3& linear_velocity_at(uint32_t slot) const {
    const uint32_t m = motion_[slot];
    return m == kNoMotion ? kZeroVelocity : motions_[m].v_WO;
  }
  const Vec3& angular_velocity_at(uint32_t slot) const {
    const uint32_t m = motion_[slot];
    return m == kNoMotion ? kZeroVelocity : motions_[m].w_WO;
  }
  Pose world_pose(ObjectId id) const { return X_WO_[SlotOf(id)]; }
  Pose local_pose(ObjectId id) const { return X_PO_[SlotOf(id)]; }
  // Sets X_PO and refreshes the world poses of the object and its subtree.
  void SetLocalPose(ObjectId id, const Pose& X_PO);
  void SetWorldPose(ObjectId id, const Pose& X_WO);
  // Dynamics backends write world poses and velocities of simulated bodies.
  // Call UpdateWorldPoses() afterwards to refresh local poses and descendants.
  // Inline: a backend calls it for every body every step.
  void SetSimulatedState(uint32_t slot, const Pose& X_WO, const Vec3& v_WO, const Vec3& w_WO) {
    X_WO_[slot] = X_WO;
    if (const uint32_t m = motion_[slot]; m != kNoMotion) motions_[m] = {v_WO, w_WO};
    simulated_[slot] = 1;
  }
  // Sets the velocity of a shape (an object with a velocity) from outside the
  // dynamics (World::SetVelocities); false, and nothing set, for any other object.
  bool SetVelocityAt(uint32_t slot, const Vec3& v_WO, const Vec3& w_WO) {
    const uint32_t m = motion_[slot];
    if (m == kNoMotion) return false;
    motions_[m] = {v_WO, w_WO};
    return true;
  }
  // Recomputes world poses top-down (the pose of each simulated body is kept
  // and its local pose derived from it).
  void UpdateWorldPoses();
  // Same, for one model instance's objects only (thread-safe across instances).
  void UpdateWorldPoses(int instance);
  // Same, for the objects outside every instance (on the calling thread).
  void UpdateSceneObjectPoses();
  // True when robots hang from no scene object and no scene object hangs from
  // a robot: then UpdateWorldPoses() equals UpdateWorldPoses(i) for every
  // instance i (in any order, concurrently) followed by UpdateSceneObjectPoses().
  bool InstancesAreIndependent() const;
  // Pose of the frame children of `slot` hang from: X_WO, times the joint
  // motion if the object is a joint.
  Pose ChildFrameAt(uint32_t slot) const;

  // --- Typed data ---------------------------------------------------------------
  const ShapeData& shape(ObjectId id) const;
  ShapeData& mutable_shape(ObjectId id);
  // Switches a shape between dynamic and kinematic/static (hybrid
  // simulation). Counts as a structural change, so dynamics backends rebuild
  // (taking velocities from the scene). Not thread-safe: call between phases.
  void SetShapeDynamic(ObjectId id, bool dynamic);
  // Sets ShapeData::surface_velocity and surface_angular_velocity. From
  // still to moving it is a structural change (the backends list a world's
  // moving surfaces when they build); other changes are read every step.
  // Not thread-safe.
  void SetSurfaceVelocity(ObjectId id, const Vec3& v_S, const Vec3& w_S);
  const JointData& joint(ObjectId id) const;
  JointData& mutable_joint(ObjectId id);
  // Dense typed tables of the built-in types. Row r belongs to the object at
  // slot *_owners()[r]. A shape is all settings: its row is a
  // Shared<ShapeData> (shared_settings.h), one ShapeData for every copy made
  // from one model entry; mutable_shape() gives the object its own first.
  SettingsView<ShapeData> shapes() const {
    return SettingsView<ShapeData>(Table<Shared<ShapeData>>(ObjectType::kShape).rows);
  }
  std::span<const uint32_t> shape_owners() const { return Owners(ObjectType::kShape); }
  // A joint's row is its state beside a Shared<JointSettings>: writing
  // through joints() or mutable_joint() changes state; a setting changes
  // through row.settings.Edit(), which gives that joint its own first.
  std::span<JointData> joints() { return Table<JointData>(ObjectType::kJoint).rows; }
  std::span<const JointData> joints() const { return Table<JointData>(ObjectType::kJoint).rows; }
  std::span<const uint32_t> joint_owners() const { return Owners(ObjectType::kJoint); }
  // Row of the object's typed data in its type's table, by slot.
  uint32_t row_at(uint32_t slot) const { return row_[slot]; }
  // The object's row (of its type's row type), or null for a type without rows.
  void* row_data(ObjectId id);

  // Dummy links (V-REP's dummy-dummy link, used by IK tip/target pairs).
  void LinkDummies(ObjectId a, ObjectId b);
  ObjectId linked_dummy(ObjectId id) const;

  // Custom data: named byte strings attached to an object (CoppeliaSim's
  // custom data blocks), copied with the object when its model is duplicated.
  // Empty `data` removes the entry. Returns null when there is none.
  // `writer` (a script's account, or null) has been charged
  // CustomDataBytes(tag, data) for the write (framework/script_memory.h):
  // the block keeps that charge until it is overwritten, removed or its
  // object goes; a removal releases it at once. A copy of the object
  // charges each writer again, whatever its limit (DuplicateSubtree throws
  // first if the run's would be passed).
  void WriteCustomData(ObjectId id, const std::string& tag, std::string data,
                       ScriptMemory* writer = nullptr);
  const std::string* ReadCustomData(ObjectId id, const std::string& tag) const;
  // Folds the slot's custom data blocks (if any) into a state hash.
  void HashCustomData(uint32_t slot, StateHasher* hasher) const;

  // --- Scripts ------------------------------------------------------------------
  void AttachScript(ObjectId id, std::shared_ptr<const ScriptSource> source,
                    bool explicit_handling = false);
  // Null if the object has no script.
  const ScriptAttachment* script(ObjectId id) const;
  const ScriptAttachment* script_at(uint32_t slot) const;

  // --- Models -------------------------------------------------------------------
  // Marks `root` as a model. A model root with no model ancestor becomes a
  // model instance (robot) with the next instance index and the given name.
  int MakeModelInstance(ObjectId root, std::string model_name, std::string instance_name);
  std::span<const ModelInstance> instances() const { return instances_; }
  const ModelInstance& instance(int index) const { return instances_.at(index); }
  // Instance index of the object's model, or -1 for scene objects.
  int instance_of_at(uint32_t slot) const { return instance_[slot]; }
  int instance_of(ObjectId id) const { return instance_[SlotOf(id)]; }
  bool is_model_root(ObjectId id) const { return model_root_[SlotOf(id)] != 0; }

  // --- Size factor (V-REP's) -----------------------------------------------------
  // Accumulated scale of the object: 1 unless it or an ancestor was scaled;
  // copied with duplication.
  double size_factor(ObjectId id) const { return size_factor_at(SlotOf(id)); }
  double size_factor_at(uint32_t slot) const {
    const auto it = size_factor_.find(slot);
    return it == size_factor_.end() ? 1.0 : it->second;
  }
  // Scales the subtree at `root` by `s` (finite, > 0) about the root's frame:
  // descendants' local positions, shape sizes, prismatic joint positions,
  // limits and speeds, sensor ranges and nozzle radii x s; masses and forces
  // x s^3, torques x s^4 (uniform density: under gravity the scaled robot
  // accelerates as the original). The size factor of every object in the
  // subtree is multiplied by s. A mesh shape gets a scaled copy of its asset
  // (one per asset per call: copies duplicated afterwards share it). A
  // structural change: dynamics backends rebuild. Not thread-safe.
  void ScaleSubtree(ObjectId root, double s);

  // Snapshots (framework/world_state.h; scene_state.cc): every live
  // object's poses, velocities and simulated flag, and the custom data;
  // LoadState into a scene of the same structure (AddStructure equal).
  void SaveState(StateWriter* out) const;
  void LoadState(StateReader* in);
  // Folds the tree into a hash: slots, liveness, types, parents, robots,
  // names and row counts (a snapshot's fingerprint).
  void AddStructure(StateHasher* hasher) const;

  // Monotonic counter bumped on every structural change (add, remove, reparent).
  uint64_t structure_version() const { return structure_version_; }

  // --- Environment map ----------------------------------------------------------
  // The static environment a world loads from a map file (environment.h),
  // or null. Set before the world starts; the modules read it at Build().
  const EnvironmentMap* environment() const { return environment_.get(); }
  void set_environment(std::shared_ptr<const EnvironmentMap> map) {
    environment_ = std::move(map);
    ++environment_version_;
  }
  // Counts set_environment calls: a module that indexed the map compares
  // this, not the pointer (a new map may reuse a freed one's address).
  uint64_t environment_version() const { return environment_version_; }

 private:
  uint32_t AllocateSlot(std::string_view name, ObjectId parent, const Pose& X_PO, ObjectType type);
  // The same with a name id the caller holds a reference to (a copy's: its
  // source's name, retained instead of looked up again).
  uint32_t AllocateSlotNamed(uint32_t name, int32_t parent_slot, const Pose& X_PO, ObjectType type);
  void FreeSlot(uint32_t slot);
  void LinkChild(uint32_t parent, uint32_t child);
  void UnlinkChild(uint32_t child);
  void RefreshSubtree(uint32_t slot);
  // UpdateWorldPoses over `slots` (parents before children).
  void UpdatePoses(std::span<const uint32_t> slots);
  void RebuildOrder() const;
  void RebuildInstanceObjects(int instance);
  uint32_t CopyObject(uint32_t src, int32_t new_parent, const Pose& X_PO);
  // A built-in type's table (the descriptor made Rows<Row> for it).
  template <typename Row>
  Rows<Row>& Table(ObjectType type) {
    return static_cast<Rows<Row>&>(*tables_[static_cast<size_t>(type)]);
  }
  template <typename Row>
  const Rows<Row>& Table(ObjectType type) const {
    return static_cast<const Rows<Row>&>(*tables_[static_cast<size_t>(type)]);
  }
  std::span<const uint32_t> Owners(ObjectType type) const {
    return tables_[static_cast<size_t>(type)]->owners;
  }

  // Per slot, hot.
  std::vector<Pose> X_PO_;  // pose in parent (slots)
  std::vector<Pose> X_WO_;  // pose in world, cached (slots)
  // Velocities in world, for shapes only (a robot has 3 shapes in 29
  // objects): motion_ (slots) indexes motions_, or is kNoMotion.
  struct Motion {
    Vec3 v_WO, w_WO;
  };
  static constexpr uint32_t kNoMotion = UINT32_MAX;
  static constexpr Vec3 kZeroVelocity{};
  std::vector<uint32_t> motion_;
  std::vector<Motion> motions_;
  std::vector<uint32_t> free_motions_;
  std::vector<int32_t> parent_;  // parent slot or -1 (slots)
  std::vector<int32_t> first_child_, last_child_, next_sibling_, prev_sibling_;  // (slots)
  std::vector<ObjectType> type_;                                                 // (slots)
  std::vector<uint32_t> row_;       // row in the type's table (slots)
  std::vector<int32_t> instance_;   // model instance or -1 (slots)
  std::vector<uint8_t> simulated_;  // pose owned by a dynamics backend this step (slots)
  // Per slot, cold.
  std::vector<uint32_t> generation_;
  std::vector<uint8_t> alive_;
  std::vector<uint8_t> model_root_;
  std::vector<uint32_t> name_;  // the name's id in names_ (slots)
  NamePool names_;
  std::vector<int32_t> script_;  // index into scripts_ or -1
  // Rare per-slot values, kept only for the slots that have one (a robot
  // has 29 objects, and none of these by default): written between phases,
  // read by scripts in parallel.
  std::unordered_map<uint32_t, uint32_t> linked_dummy_;  // slot -> its linked dummy's slot
  // Custom data, for objects that have some.
  struct CustomDataBlock {
    std::string data;
    ScriptMemory* writer = nullptr;  // charged for it (WriteCustomData)
  };
  using CustomData = std::map<std::string, CustomDataBlock>;
  std::unordered_map<uint32_t, CustomData> custom_data_;
  // Releases the writers' charges for the slot's blocks and drops them.
  void DropCustomData(uint32_t slot);
  std::unordered_map<uint32_t, double> size_factor_;  // accumulated scale where not 1
  std::vector<uint32_t> free_slots_;
  size_t object_count_ = 0;

  // Object types and their row tables, by ObjectType value (a table is null
  // for a type without rows).
  std::vector<const ObjectTypeDescriptor*> types_;
  std::vector<const char*> type_names_;  // types_[t]->name, for type_name() inline
  std::vector<std::unique_ptr<RowTable>> tables_;
  std::vector<ObjectType> listing_order_;  // ListingOrder(types_)
  std::shared_ptr<const EnvironmentMap> environment_;
  uint64_t environment_version_ = 0;

  std::vector<ScriptAttachment> scripts_;
  std::vector<ModelInstance> instances_;

  // Topological order of all live slots (parents first), rebuilt lazily.
  mutable std::vector<uint32_t> order_;
  mutable std::vector<uint32_t> scene_order_;  // order_ without instance objects
  mutable bool instances_independent_ = true;
  mutable bool order_dirty_ = true;
  uint64_t structure_version_ = 0;
  // What a path lookup's walk depends on besides the structure: which scene
  // this is (a number no other scene in the process has) and its renames.
  // FindObject resumes a thread's last walk only while all three are as then.
  uint64_t serial_ = 0;
  uint64_t renames_ = 0;
  std::vector<SceneListener*> listeners_;
};

}  // namespace swarmsim
