#include "modules/dynamics/ode/ode_world.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/scene.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "modules/dynamics/environment_obstacles.h"
#include "modules/dynamics/ode/ode_internal.h"
#include "modules/dynamics/ode/ode_threading.h"
#include "modules/dynamics/scene_walk.h"

namespace swarmsim::ode {

namespace {

using dynamics::PathAt;
using dynamics::ShapeAt;
using dynamics::ThrowIfNotFinite;

// A geom for the shape, or null if its size cannot make one. `mesh_data`:
// the trimesh data of a mesh shape.
dGeomID MakeGeom(dSpaceID space, const ShapeData& shape, dTriMeshDataID mesh_data) {
  const Vec3& s = shape.size;
  switch (shape.kind) {
    case ShapeKind::kBox:
      if (!(s.x > 0 && s.y > 0 && s.z > 0)) return nullptr;
      return dCreateBox(space, s.x, s.y, s.z);
    case ShapeKind::kSphere:
      if (!(s.x > 0)) return nullptr;
      return dCreateSphere(space, s.x);
    case ShapeKind::kCylinder:
      if (!(s.x > 0 && s.z > 0)) return nullptr;
      return dCreateCylinder(space, s.x, s.z);
    case ShapeKind::kCapsule:
      if (!(s.x > 0)) return nullptr;
      return dCreateCapsule(space, s.x, std::max(0.0, s.z - 2 * s.x));
    case ShapeKind::kMesh:
      if (!mesh_data) return nullptr;
      return dCreateTriMesh(space, mesh_data, nullptr, nullptr, nullptr);
  }
  return nullptr;
}

// Mass and inertia of the solid shape, about its centre, in its frame.
dMass CalcMass(const ShapeData& shape) {
  dMass m;
  const Vec3& s = shape.size;
  if (shape.inertia[0] > 0) {  // given (a URDF <inertial>): about the centre of mass, shape's axes
    const auto& i = shape.inertia;
    dMassSetParameters(&m, shape.mass, 0, 0, 0, i[0], i[1], i[2], i[3], i[4], i[5]);
    return m;
  }
  switch (shape.kind) {
    case ShapeKind::kBox: dMassSetBoxTotal(&m, shape.mass, s.x, s.y, s.z); break;
    case ShapeKind::kSphere: dMassSetSphereTotal(&m, shape.mass, s.x); break;
    case ShapeKind::kCylinder: dMassSetCylinderTotal(&m, shape.mass, 3, s.x, s.z); break;
    case ShapeKind::kCapsule:
      dMassSetCapsuleTotal(&m, shape.mass, 3, s.x, std::max(0.0, s.z - 2 * s.x));
      break;
    case ShapeKind::kMesh: {
      // The mass sits at the shape's origin (ODE wants it at the body's
      // origin: put a mesh's origin at its centre of mass); the inertia is
      // that of the mesh's bounding box, about the origin (the box's own
      // inertia plus the parallel-axis term of its offset).
      const Vec3 lo = shape.mesh ? shape.mesh->lo() : s * -0.5;
      const Vec3 hi = shape.mesh ? shape.mesh->hi() : s * 0.5;
      const Vec3 e = hi - lo, c = (lo + hi) * 0.5;
      dMassSetBoxTotal(&m, shape.mass, std::max(e.x, 1e-9), std::max(e.y, 1e-9),
                       std::max(e.z, 1e-9));
      dMassTranslate(&m, c.x, c.y, c.z);
      m.c[0] = m.c[1] = m.c[2] = 0;
      break;
    }
  }
  return m;
}

// A dynamic shape's body sits at its centre of mass p_SC (ODE's bodies
// have theirs at their origin): the body's pose and velocity from the
// shape's, and back.
// (No arithmetic at all for a centre at the origin, so that those
// shapes' states stay bit for bit what they were.)
Pose BodyPoseOf(const Pose& X_WS, const Vec3& p_SC) {
  return p_SC == Vec3{} ? X_WS : Pose{X_WS * p_SC, X_WS.q};
}
Pose ShapePoseOf(const Pose& X_WC, const Vec3& p_SC) {
  return p_SC == Vec3{} ? X_WC : Pose{X_WC * -p_SC, X_WC.q};
}
// The velocity of the point at `offset` (world axes) from one moving at v, w.
Vec3 PointVelocity(const Vec3& v, const Vec3& w, const Vec3& offset) {
  return offset == Vec3{} ? v : v + w.Cross(offset);
}

// Angular velocity that turns q_from into q_to in `duration` seconds.
Vec3 AngularVelocity(const Quat& q_from, const Quat& q_to, double duration) {
  Quat dq = (q_to * q_from.Conjugate()).Normalized();
  if (dq.w < 0) dq = {-dq.w, -dq.x, -dq.y, -dq.z};
  const Vec3 v{dq.x, dq.y, dq.z};
  const double s = v.Norm();
  if (s < 1e-15) return {};
  return v * (2 * std::atan2(s, dq.w) / (s * duration));
}

Pose Interpolate(const Pose& a, const Pose& b, double f) {
  Quat qb = b.q;
  if (a.q.w * qb.w + a.q.x * qb.x + a.q.y * qb.y + a.q.z * qb.z < 0)
    qb = {-qb.w, -qb.x, -qb.y, -qb.z};
  const Quat q{a.q.w + (qb.w - a.q.w) * f, a.q.x + (qb.x - a.q.x) * f, a.q.y + (qb.y - a.q.y) * f,
               a.q.z + (qb.z - a.q.z) * f};
  return {a.p + (b.p - a.p) * f, q.Normalized()};
}

// What carries a non-dynamic shape: the body of its nearest dynamic ancestor
// when no joint or force sensor lies between them (the shape is a part of
// it), else none; and whether a joint or force sensor lies above it on the
// way to that ancestor (or to the root).
struct Carrier {
  dBodyID body = nullptr;
  bool below_joint = false;
};
Carrier CarrierOf(const Scene& scene, const std::vector<dBodyID>& body_of, uint32_t slot) {
  Carrier carrier;
  ObjectType sensor_type = ObjectType::kJoint;  // stays kJoint when there is no such type
  force_sensor::FindType(scene, &sensor_type);
  for (int32_t p = scene.parent_at(slot); p >= 0; p = scene.parent_at(static_cast<uint32_t>(p))) {
    const uint32_t ps = static_cast<uint32_t>(p);
    if (scene.type_at(ps) == ObjectType::kJoint || scene.type_at(ps) == sensor_type)
      carrier.below_joint = true;
    const ShapeData* ancestor = ShapeAt(scene, ps);
    if (ancestor && ancestor->dynamic) {
      if (!carrier.below_joint) carrier.body = body_of[ps];
      break;
    }
  }
  return carrier;
}

}  // namespace

OdeWorld::OdeWorld(const Options& options, const DynamicsSettings& settings)
    : options_(options), settings_(settings) {
  // The world file's settings (simulation.ode) replace the backend's own.
  if (const auto* given = dynamic_cast<const WorldOptions*>(settings_.options.get()))
    options_ = given->options;
  if (!std::isfinite(settings_.gravity))
    throw Error("ode: gravity must be a finite number, got " + std::to_string(settings_.gravity));
  // dCollide takes the contact count in the low 16 bits of its flags.
  if (options_.max_contacts < 1 || options_.max_contacts > 0xffff || options_.iterations < 0)
    throw Error("ode: max_contacts must be in 1..65535 and iterations >= 0");
  InitOdeOnce();
}

OdeWorld::~OdeWorld() {
  Clear();
  if (threading_) dThreadingFreeImplementation(threading_);
}

void OdeWorld::Clear() {
  if (broken_) {
    // Unwound out of an ODE call: its space may still be locked and its
    // destructors would assert again. The process ends with the run; leak,
    // kept reachable from a global so that leak checkers see a choice
    // (LeakSanitizer reports only what nothing points to).
    static auto* const unwound = new std::vector<const void*>;
    unwound->insert(unwound->end(), {contacts_, space_, world_, threading_,
                                     static_cast<const void*>(solver_threads_.get())});
    for (const auto& [mesh, data] : meshes_) unwound->push_back(data);
    contacts_ = nullptr;
    space_ = nullptr;
    world_ = nullptr;
    threading_ = nullptr;             // (in use by the unwound step: leaked)
    (void)solver_threads_.release();  // likewise (its threads stay asleep)
    meshes_.clear();                  // (their trimesh data leaks with the geoms)
    broken_ = false;
  }
  if (contacts_) dJointGroupDestroy(contacts_);
  if (space_) dSpaceDestroy(space_);  // destroys its geoms
  if (world_) {
    dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
    dWorldDestroy(world_);  // destroys bodies and joints
  }
  for (auto& [mesh, data] : meshes_) dGeomTriMeshDataDestroy(data);  // after their geoms
  meshes_.clear();
  single_triangle_meshes_.clear();  // after the data that points at them
  contacts_ = nullptr;
  space_ = nullptr;
  world_ = nullptr;
  bodies_.clear();
  kinematic_.clear();
  static_geoms_.clear();
  joints_.clear();
  force_sensors_.clear();
  has_mounts_ = false;
  feedback_.clear();
  geom_info_.clear();
  surfaces_.clear();
  instance_spaces_.clear();  // destroyed with space_
  pairs_.clear();
  has_meshes_ = false;
  commands_.clear();
}

void OdeWorld::AddGeom(dGeomID geom, int32_t instance, double friction, double restitution) {
  geom_info_.push_back({instance, -1, friction, restitution});
  dGeomSetData(geom, reinterpret_cast<void*>(static_cast<uintptr_t>(geom_info_.size())));
}

void OdeWorld::AddSurface(const ShapeData& shape, uint32_t slot) {
  if (!shape.HasMovingSurface()) return;
  geom_info_.back().surface = static_cast<int32_t>(surfaces_.size());
  surfaces_.push_back({slot, shape.surface_velocity, shape.surface_angular_velocity});
}

dTriMeshDataID OdeWorld::MeshData(const std::shared_ptr<const TriangleMesh>& mesh) {
  static_assert(sizeof(dTriIndex) == sizeof(uint32_t) && sizeof(MeshTriangle) == 12 &&
                sizeof(Vec3) == 3 * sizeof(double));
  if (!mesh) return nullptr;
  for (const auto& [known, data] : meshes_)
    if (known == mesh) return data;
  // Few distinct meshes per world: a linear search is fine.
  has_meshes_ = true;
  dTriMeshDataID data = dGeomTriMeshDataCreate();
  std::span<const MeshTriangle> triangles = mesh->triangles();
  if (triangles.size() == 1) {
    // OPCODE's tree-against-tree collider dereferences null on a tree of one
    // leaf: give a one-triangle mesh its back face too (ODE keeps the
    // pointer, so the buffer lives as long as the data).
    const MeshTriangle& t = triangles[0];
    single_triangle_meshes_.push_back({t, MeshTriangle{{t.v[0], t.v[2], t.v[1]}}});
    triangles = single_triangle_meshes_.back();
  }
  dGeomTriMeshDataBuildDouble(data, mesh->vertices().data(), sizeof(Vec3),
                              static_cast<int>(mesh->vertices().size()), triangles.data(),
                              static_cast<int>(3 * triangles.size()), sizeof(MeshTriangle));
  meshes_.emplace_back(mesh, data);
  return data;
}

void OdeWorld::Build(const Scene& scene) {
  // The environment map's voxels the dynamic shapes can meet, merged into boxes.
  const std::vector<EnvironmentBox> map_boxes =
      dynamics::EnvironmentObstacles(scene, dynamics::DynamicHeightRange(scene), false);
  // 0. A fresh ODE world, collision space and contact group (and the ground plane).
  CreateWorld();
  // 1. A body per dynamic shape, in slot order.
  std::vector<dBodyID> body_of(scene.slot_count(), nullptr);  // dynamic or kinematic body (slots)
  BuildBodies(scene, &body_of);
  // 2. Non-dynamic shapes: parts of a body, kinematic bodies or static geoms;
  // then the map's boxes, static geoms of the default material. Merged boxes
  // touch each other: their category keeps the space from pairing them at
  // all (they would only be dropped by Collide, every substep).
  BuildNonDynamicShapes(scene, &body_of);
  const ShapeData material;
  constexpr unsigned long kMapCategory = 1ul << 31;
  for (const EnvironmentBox& box : map_boxes) {
    const Vec3 size = box.hi - box.lo, centre = (box.lo + box.hi) * 0.5;
    dGeomID geom = dCreateBox(space_, size.x, size.y, size.z);
    dGeomSetPosition(geom, centre.x, centre.y, centre.z);
    dGeomSetCategoryBits(geom, kMapCategory);
    dGeomSetCollideBits(geom, ~kMapCategory);
    AddGeom(geom, -1, material.friction, material.restitution);
  }
  // 3. Joints with a dynamic child body, in slot order.
  BuildJoints(scene, body_of);
  // 4. Force sensors.
  if (force_sensor::Any(scene)) BuildForceSensors(scene, body_of);
  LinkDependentJoints(scene);
  commands_.assign(joints_.size(), JointCommand{});
  motor_velocity_.assign(joints_.size(), 0.0);
  // The stepper: auto is exact for small worlds (an arm, a few robots), where
  // it is cheap and holds joints to round-off; iterative for swarms.
  switch (options_.solver) {
    case Solver::kWorld: exact_solver_ = true; break;
    case Solver::kQuickStep: exact_solver_ = options_.iterations <= 0; break;
    case Solver::kAuto:
      // Exact for small worlds of mostly fixed-base mechanisms (arms: two
      // thirds of the bodies or more hang through joints from the world or
      // a kinematic base). Free bodies in contact make the direct solve's
      // LCP degenerate: boxes stacked into towers fall, a wheeled base
      // dropped on the ground lands yawed ("LCP internal error"), a
      // humanoid standing on its feet with 2 mg finger links stops the run
      // (dxLDLTRemove); quickstep holds them all.
      exact_solver_ =
          options_.iterations <= 0 || (bodies_.size() <= static_cast<size_t>(kExactSolverBodies) &&
                                       3 * AnchoredBodies() >= 2 * bodies_.size());
      break;
  }
}

size_t OdeWorld::AnchoredBodies() const {
  // Union-find over the dynamic bodies; index bodies_.size() stands for the
  // world and every kinematic body (a robot's fixed base).
  std::unordered_map<dBodyID, size_t> index;
  for (size_t k = 0; k < bodies_.size(); ++k) index.emplace(bodies_[k].body, k);
  const size_t anchor = bodies_.size();
  std::vector<size_t> up(bodies_.size() + 1);
  for (size_t k = 0; k < up.size(); ++k) up[k] = k;
  const auto find = [&](size_t k) {
    while (up[k] != k) k = up[k] = up[up[k]];
    return k;
  };
  const auto node = [&](dBodyID body) {
    const auto it = body == nullptr ? index.end() : index.find(body);
    return it == index.end() ? anchor : it->second;  // the world, or a kinematic body
  };
  for (const SimJoint& j : joints_) {
    size_t a = find(node(j.parent_body)), b = find(node(j.child_body));
    if (a == b) continue;
    if (b == anchor) std::swap(a, b);
    up[b] = a;  // the anchor stays a root
  }
  size_t anchored = 0;
  for (size_t k = 0; k < bodies_.size(); ++k) anchored += find(k) == anchor;
  return anchored;
}

dSpaceID OdeWorld::SpaceOf(int32_t instance) {
  if (instance < 0) return space_;
  const size_t i = static_cast<size_t>(instance);
  if (i >= instance_spaces_.size()) instance_spaces_.resize(i + 1, nullptr);
  if (!instance_spaces_[i]) instance_spaces_[i] = dSimpleSpaceCreate(space_);
  return instance_spaces_[i];
}

void OdeWorld::CreateWorld() {
  Clear();
  dAllocateODEDataForThread(dAllocateMaskAll);
  dRandSetSeed(options_.seed);
  world_ = dWorldCreate();
  // The solver's threads (ode_threading.h), made once per OdeWorld (a
  // rebuild keeps them): islands stepped concurrently, each on one thread,
  // the same state for any thread count, 1 included. ODE's own
  // single-threaded implementation only when the shuffle is not ours.
  if (!solver_threads_ && !threading_) {
    if (SolverShuffleIsOurs()) {
      solver_threads_ = std::make_unique<SolverThreads>(settings_.scheduler, world_);
    } else {
      threading_ = dThreadingAllocateSelfThreadedImplementation();
    }
  }
  if (solver_threads_) {
    solver_threads_->set_world(world_);
    dWorldSetStepThreadingImplementation(world_, solver_threads_->functions(),
                                         solver_threads_->id());
  } else {
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                         threading_);
  }
  dWorldSetGravity(world_, 0, 0, -settings_.gravity);
  dWorldSetERP(world_, options_.erp);
  dWorldSetCFM(world_, options_.cfm);
  dWorldSetQuickStepNumIterations(world_, std::max(1, options_.iterations));
  dWorldSetContactSurfaceLayer(world_, 1e-4);
  dWorldSetContactMaxCorrectingVel(world_, 10);
  // Spaces (see ode_world.h): a sweep-and-prune space over the robots'
  // sub-spaces (one dSimpleSpace per model instance, created on its first
  // geom) and the geoms outside any robot (statics, loose dynamic objects,
  // the ground plane). A robot's geoms are never paired with each other (no
  // self-collision), so its sub-space only ever meets other geoms. Memory
  // and broadphase cost grow with the robot count, not its square (ODE's
  // hash space keeps an n x n bit table of tested pairs).
  space_ = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  contacts_ = dJointGroupCreate(0);
  if (options_.ground_plane) {
    AddGeom(dCreatePlane(space_, 0, 0, 1, 0), -1, options_.ground_friction, 0);
  }
}

void OdeWorld::BuildBodies(const Scene& scene, std::vector<dBodyID>* body_of) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = ShapeAt(scene, s);
    if (!shape || !shape->dynamic) continue;
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("ode", scene, s, X_WS);
    if (!(shape->mass > 0) || !std::isfinite(shape->mass))
      throw Error("ode: dynamic shape '" + PathAt(scene, s) + "' needs a positive mass (got " +
                  std::to_string(shape->mass) + " kg)");
    // A shape that is not collidable carries its mass without a geom.
    dGeomID geom = shape->collidable
                       ? MakeGeom(SpaceOf(scene.instance_of_at(s)), *shape, MeshData(shape->mesh))
                       : nullptr;
    if (!geom && shape->collidable)
      throw Error("ode: dynamic shape '" + PathAt(scene, s) + "' needs a positive size");
    dBodyID body = dBodyCreate(world_);
    const Vec3& p_SC = shape->center_of_mass;
    SetBodyPose(body, BodyPoseOf(X_WS, p_SC));
    const Vec3& w = scene.angular_velocity_at(s);
    const Vec3 v = PointVelocity(scene.linear_velocity_at(s), w, X_WS.q.Rotate(p_SC));
    dBodySetLinearVel(body, v.x, v.y, v.z);
    dBodySetAngularVel(body, w.x, w.y, w.z);
    const dMass mass = CalcMass(*shape);
    dBodySetMass(body, &mass);
    if (geom) {
      dGeomSetBody(geom, body);
      if (!(p_SC == Vec3{})) dGeomSetOffsetPosition(geom, -p_SC.x, -p_SC.y, -p_SC.z);
      AddGeom(geom, scene.instance_of_at(s), shape->friction, shape->restitution);
      AddSurface(*shape, s);
    }
    (*body_of)[s] = body;
    bodies_.push_back({body, s, X_WS, p_SC});
  }
}

void OdeWorld::BuildNonDynamicShapes(const Scene& scene, std::vector<dBodyID>* body_of) {
  for (uint32_t s = 0; s < scene.slot_count(); ++s) {
    const ShapeData* shape = ShapeAt(scene, s);
    if (!shape || shape->dynamic || !shape->collidable) continue;
    const Pose& X_WS = scene.world_pose_at(s);
    ThrowIfNotFinite("ode", scene, s, X_WS);
    const Carrier carrier = CarrierOf(scene, *body_of, s);
    dGeomID geom = MakeGeom(SpaceOf(scene.instance_of_at(s)), *shape, MeshData(shape->mesh));
    if (!geom) continue;  // a zero-size decoration: nothing to collide with
    AddGeom(geom, scene.instance_of_at(s), shape->friction, shape->restitution);
    AddSurface(*shape, s);
    if (carrier.body) {
      dGeomSetBody(geom, carrier.body);
      dGeomSetOffsetWorldPosition(geom, X_WS.p.x, X_WS.p.y, X_WS.p.z);
      const dQuaternion q = {X_WS.q.w, X_WS.q.x, X_WS.q.y, X_WS.q.z};
      dGeomSetOffsetWorldQuaternion(geom, q);
    } else if (carrier.below_joint || scene.instance_of_at(s) >= 0) {
      dBodyID body = dBodyCreate(world_);
      dBodySetKinematic(body);
      SetBodyPose(body, X_WS);
      dGeomSetBody(geom, body);
      (*body_of)[s] = body;
      kinematic_.push_back({body, s, X_WS, X_WS, {}, {}});
    } else {
      dGeomSetPosition(geom, X_WS.p.x, X_WS.p.y, X_WS.p.z);
      const dQuaternion q = {X_WS.q.w, X_WS.q.x, X_WS.q.y, X_WS.q.z};
      dGeomSetQuaternion(geom, q);
      static_geoms_.push_back({geom, s, X_WS});
    }
  }
}

void OdeWorld::MarkJoints(Scene* scene) const {
  for (JointData& j : scene->joints()) j.simulated = false;
  for (const SimJoint& j : joints_) scene->joints()[j.row].simulated = true;
}

void OdeWorld::SyncFromScene(const Scene& scene, double duration) {
  dAllocateODEDataForThread(dAllocateMaskAll);
  // Bodies moved by a script since the last write-back: teleport them.
  for (DynamicBody& b : bodies_) {
    const Pose& X_WB = scene.world_pose_at(b.slot);
    if (X_WB == b.X_WB_written) continue;
    SetBodyPose(b.body, BodyPoseOf(X_WB, b.p_SC));
    const Vec3& w = scene.angular_velocity_at(b.slot);
    const Vec3 v = PointVelocity(scene.linear_velocity_at(b.slot), w, X_WB.q.Rotate(b.p_SC));
    dBodySetLinearVel(b.body, v.x, v.y, v.z);
    dBodySetAngularVel(b.body, w.x, w.y, w.z);
    b.X_WB_written = X_WB;
  }
  FollowStaticGeoms(scene);  // ode_static_geoms.cc
  // Kinematic bodies go from where they were to where the scene has them.
  for (KinematicBody& k : kinematic_) {
    k.X_WB_from = k.X_WB_to;
    k.X_WB_to = scene.world_pose_at(k.slot);
    if ((k.X_WB_to.p - k.X_WB_from.p).Norm() > k.jump) {
      k.X_WB_from = k.X_WB_to;  // a jump: there now, at rest
      k.v_WB = k.w_WB = {};
      continue;
    }
    k.v_WB = (k.X_WB_to.p - k.X_WB_from.p) / duration;
    k.w_WB = AngularVelocity(k.X_WB_from.q, k.X_WB_to.q, duration);
  }
}

void OdeWorld::ReadCommands(const Scene& scene) {
  for (size_t k = 0; k < joints_.size(); ++k) {
    const JointData& j = scene.joints()[joints_[k].row];
    const JointSettings& settings = *j.settings;
    commands_[k] = {.type = settings.type,
                    .mode = settings.mode,
                    .target_velocity = j.DriveVelocity(),
                    .target_position = j.target_position,
                    .target_force = j.target_force,
                    .max_force = settings.max_force,
                    .max_velocity = settings.max_velocity,
                    .damping = settings.damping};
  }
  for (MovingSurface& surface : surfaces_) {
    const ShapeData& shape = scene.shapes()[scene.row_at(surface.slot)];
    surface.v_S = shape.surface_velocity;
    surface.w_S = shape.surface_angular_velocity;
  }
}

void OdeWorld::Substep(double dt, double fraction) {
  try {
    StepOnce(dt, fraction);
  } catch (...) {
    broken_ = true;  // ODE was left mid-call (ThrowOdeError): Clear leaks it
    throw;
  }
}

void OdeWorld::StepOnce(double dt, double fraction) {
  step_dt_ = dt;
  for (KinematicBody& k : kinematic_) {
    SetBodyPose(k.body, Interpolate(k.X_WB_from, k.X_WB_to, fraction));
    dBodySetLinearVel(k.body, k.v_WB.x, k.v_WB.y, k.v_WB.z);
    dBodySetAngularVel(k.body, k.w_WB.x, k.w_WB.y, k.w_WB.z);
  }
  ApplyMotors(dt);
  // The contact joints (ode_contacts.cc): the same joints in the same order
  // for any thread count.
  FindCandidatePairs();
  FindContacts();
  for (size_t k = 0; k < pairs_.size(); ++k) AddContacts(k);
  // Each substep's constraint shuffles start from their own seed (DrawShuffle).
  ++substeps_done_;
  if (solver_threads_)
    solver_threads_->set_shuffle_seed(Mix64(Mix64(options_.seed) ^ substeps_done_));
  int stepped = 0;
  try {
    stepped = exact_solver_ ? dWorldStep(world_, dt) : dWorldQuickStep(world_, dt);
    if (solver_threads_) {
      if (std::exception_ptr failure = solver_threads_->TakeFailure())
        std::rethrow_exception(failure);
    }
  } catch (const Error& e) {
    if (!exact_solver_) throw;
    throw Error(std::string(e.what()) +
                "; this world uses ODE's exact solver (`solver: world`, or `auto` for a small "
                "world of fixed-base arms), which fails on degenerate constraint sets (links of "
                "a few milligrams, many contacts): `simulation: {ode: {solver: quickstep}}` may "
                "hold it");
  }
  if (!stepped) throw Error("ode: the solver could not step (out of memory?)");
  dJointGroupEmpty(contacts_);
  TrackJointPositions();
}

void OdeWorld::WriteBack(Scene* scene) {
  if (!force_sensors_.empty()) ReadForceSensors(scene);
  for (KinematicBody& k : kinematic_) SetBodyPose(k.body, k.X_WB_to);
  for (DynamicBody& b : bodies_) {
    const Pose X_WC = BodyPose(b.body);
    const Pose X_WS = ShapePoseOf(X_WC, b.p_SC);
    const Vec3 w = ToVec3(dBodyGetAngularVel(b.body));
    const Vec3 p_CS = b.p_SC == Vec3{} ? Vec3{} : X_WS.p - X_WC.p;
    scene->SetSimulatedState(b.slot, X_WS,
                             PointVelocity(ToVec3(dBodyGetLinearVel(b.body)), w, p_CS), w);
    b.X_WB_written = X_WS;
  }
  for (size_t k = 0; k < joints_.size(); ++k) {
    const SimJoint& j = joints_[k];
    JointData& data = scene->joints()[j.row];
    switch (commands_[k].type) {
      case JointType::kRevolute:
        data.position = j.position;
        data.velocity = dJointGetHingeAngleRate(j.joint);
        break;
      case JointType::kPrismatic:
        data.position = j.position;
        data.velocity = dJointGetSliderPositionRate(j.joint);
        break;
      case JointType::kSpherical: {
        const Pose X_WJ = j.parent_body ? BodyPose(j.parent_body) * j.X_AJ : j.X_AJ;
        const Quat q_JB = X_WJ.q.Conjugate() * BodyPose(j.child_body).q;
        data.ball = (q_JB * j.q_JB0.Conjugate() * j.ball0).Normalized();
        break;
      }
      case JointType::kScrew:
      case JointType::kFixed: break;
    }
  }
}

void OdeWorld::Hash(StateHasher* hasher) const {
  for (const DynamicBody& b : bodies_) {
    hasher->AddValue(BodyPose(b.body));
    hasher->AddValue(ToVec3(dBodyGetLinearVel(b.body)));
    hasher->AddValue(ToVec3(dBodyGetAngularVel(b.body)));
  }
  for (const KinematicBody& k : kinematic_) hasher->AddValue(k.X_WB_to);
  for (const SimJoint& j : joints_) {
    hasher->AddValue(j.position);
    hasher->AddValue(j.last_angle);
  }
  const uint64_t seed = dRandGetSeed();
  hasher->AddValue(seed);
  hasher->AddValue(substeps_done_);
}

}  // namespace swarmsim::ode
