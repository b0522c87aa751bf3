// The ODE world behind the backend: bodies, geoms and joints mirrored from
// a scene. Internal to the module; see ode_backend.h for the rules.
#pragma once

#include <ode/ode.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/math.h"
#include "framework/scene.h"
#include "modules/dynamics/ode/ode_options.h"

namespace swarmsim {
class Scene;
class StateHasher;
}  // namespace swarmsim

namespace swarmsim::ode {

class SolverThreads;  // ode_threading.h

// How the solver uses threads in this process (ODE initialised and probed
// once), for the module's description.
std::string SolverThreading();

// A dynamic body: one per dynamic shape.
struct DynamicBody {  // 96 bytes
  dBodyID body;       // ODE's body sits at the shape's centre of mass
  uint32_t slot;
  Pose X_WB_written;  // the shape's pose last written to the scene (detects teleports)
  Vec3 p_SC;          // the centre of mass in the shape (ShapeData::center_of_mass)
};

// A non-dynamic shape moved by the scene and pushed into ODE.
// A static shape's geom (no body), and the world pose it was built at.
struct StaticGeom {
  dGeomID geom;
  uint32_t slot;
  Pose X_WS;
};

struct KinematicBody {  // 136 bytes
  dBodyID body;
  uint32_t slot;
  Pose X_WB_from, X_WB_to;  // pose at the start and end of the current step
  Vec3 v_WB, w_WB;
  // A step's move longer than this (m) is a jump: the body is put at its new
  // pose, at rest, instead of sweeping there (a static shape that a script
  // or a path moved; a robot's kinematic parts always sweep).
  double jump = std::numeric_limits<double>::infinity();
};

// A joint's command for one step, copied from its row and its settings
// (ReadCommands) so that the substeps read no scene rows. 56 bytes; the
// defaults are a default JointData's.
struct JointCommand {
  JointType type = JointType::kRevolute;
  JointMode mode = JointMode::kVelocity;
  double target_velocity = 0;  // rad/s or m/s
  double target_position = 0;  // rad or m
  double target_force = 0;     // N or N m
  double max_force = 10;       // N or N m
  double max_velocity = 10;    // rad/s or m/s
  double damping = 0;          // N m s/rad or N s/m
};

struct SimJoint {
  dJointID joint;
  uint32_t slot;        // scene slot of the joint object
  uint32_t row;         // row in Scene::joints()
  double offset;        // scene position ODE measures from (at Build; `wide`: moves)
  double last_angle;    // last raw hinge angle, for unwrapping
  double position;      // unwrapped position, rad or m
  dBodyID parent_body;  // A, or null for the static world
  Pose X_AJ;            // joint frame in A (in the world if A is null)
  Quat q_JB0, ball0;    // spherical: child rotation in J and ball at Build
  dBodyID child_body;
  // A dependent joint (a URDF mimic) whose master ODE simulates too: its
  // index in joints_, and q = master_offset + master_factor * q_master. -1: none.
  int32_t master = -1;
  double master_factor = 1, master_offset = 0;
  // Stops ODE holds (hinge: set only within (-pi, pi] of the Build
  // position), in scene positions, and whether ApplyMotors released one for
  // this substep: a motor driving the joint off a stop it rests on.
  bool has_stops = false;
  // A hinge whose limits lie farther than pi from the Build position (a
  // Panda's joint6 up to 3.75 rad, a Jaco's 0.82 to 5.46): ODE measures the
  // angle in (-pi, pi], so its reference (`offset`) moves to the joint as
  // it nears a stop or the wrap (ApplyMotors) and the stops are set around it.
  bool wide = false;
  double min_position = 0, max_position = 0;
  bool lo_released = false, hi_released = false;
};

// A force sensor: a fixed joint with feedback between its child body and the
// nearest body above (or the world). ode_force_sensors.cc.
struct SimForceSensor {
  dJointID joint;      // null once broken
  uint32_t row;        // row in the force sensor rows (modules/force_sensor)
  dBodyID child_body;  // body 1 of the joint
  Pose X_BS;           // sensor frame in the child body
  dJointFeedback* feedback;
  // The static geom the sensor hangs from when its parent has no body (a
  // static shape): while the link holds, the child does not touch it (the
  // joint, not a contact, carries the load, as between two bodies).
  dGeomID mount;
};

// Per geom: owner info for the contact filter and materials.
struct GeomInfo {        // 24 bytes
  int32_t instance;      // model instance or -1
  int32_t surface = -1;  // index into OdeWorld::surfaces_, or -1: not a moving surface
  double friction;
  double restitution;
};

// A shape whose surface moves (ShapeData::surface_velocity: a conveyor
// belt's segment), read from the scene every step.
struct MovingSurface {  // 56 bytes
  uint32_t slot;
  Vec3 v_S, w_S;  // m/s, rad/s in the shape's frame (ShapeData::surface_*)
};

class OdeWorld {
 public:
  // For EngineBackend (engine_backend.h), which runs the step below.
  using Options = ode::Options;
  static constexpr std::string_view kName = "ode";
  // SyncFromScene divides by the step's duration: no substeps, no step.
  static constexpr bool kIdleWithoutSubsteps = true;

  OdeWorld(const Options& options, const DynamicsSettings& settings);
  ~OdeWorld();
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

  void Build(const Scene& scene);
  void MarkJoints(Scene* scene) const;
  // Moves bodies teleported by scripts and reads the kinematic bodies' new
  // poses (to be reached over `duration` seconds).
  void SyncFromScene(const Scene& scene, double duration);
  // A static geom whose shape moved becomes a kinematic body (SyncFromScene;
  // ode_static_geoms.cc).
  void FollowStaticGeoms(const Scene& scene);
  // Reads the joint commands (targets, forces) that set the motors.
  void ReadCommands(const Scene& scene);
  // One ODE step of `dt`; `fraction` in [0, 1] is how far through the control
  // step it starts (kinematic bodies are placed there and move at their
  // step's velocity).
  void Substep(double dt, double fraction);
  void WriteBack(Scene* scene);
  void Hash(StateHasher* hasher) const;
  int body_count() const { return static_cast<int>(bodies_.size()); }

 private:
  void Clear();
  // Build's phases, in order. 0: a fresh world, its spaces (sweep and prune
  // over the robots' sub-spaces and the other geoms), contact group and
  // ground plane.
  void CreateWorld();
  // 1. A body and geom per dynamic shape, in slot order; fills body_of (slots).
  void BuildBodies(const Scene& scene, std::vector<dBodyID>* body_of);
  // 2. A geom per other shape: a part of a body, a kinematic body (added to
  // body_of) or a static geom.
  void BuildNonDynamicShapes(const Scene& scene, std::vector<dBodyID>* body_of);
  // 3. An ODE joint per joint with a dynamic child body, in slot order.
  void BuildJoints(const Scene& scene, const std::vector<dBodyID>& body_of);
  void AddJoint(const Scene& scene, uint32_t slot, dBodyID child, dBodyID parent);
  void StepOnce(double dt, double fraction);  // Substep's work
  // Fixed joints with feedback for the scene's force sensors (ode_force_sensors.cc).
  void BuildForceSensors(const Scene& scene, const std::vector<dBodyID>& body_of);
  // The geom of the static shape a force sensor hangs from (nearest shape
  // above it), or null.
  dGeomID MountGeom(const Scene& scene, uint32_t sensor_slot) const;
  // Is (a, b) a force sensor's child against the static shape it hangs
  // from, the link holding? (ba, bb: their bodies.)
  bool HeldApart(dGeomID a, dBodyID ba, dGeomID b, dBodyID bb) const;
  // Samples each sensor's joint feedback and breaks links over their threshold.
  void ReadForceSensors(Scene* scene);
  void AddGeom(dGeomID geom, int32_t instance, double friction, double restitution);
  // The geom last added is the shape at `slot`: listed as a moving surface
  // if the shape has a surface velocity.
  void AddSurface(const ShapeData& shape, uint32_t slot);
  // The world velocity of a geom's surface at p_W (zero if it does not move).
  Vec3 SurfaceVelocity(dGeomID geom, const GeomInfo& info, const Vec3& p_W) const;
  // ODE's trimesh data for a mesh asset, made once per world (ode_world.cc).
  dTriMeshDataID MeshData(const std::shared_ptr<const TriangleMesh>& mesh);
  void ApplyMotors(double dt);
  // Links each dependent joint to its master's index (SimJoint::master).
  void LinkDependentJoints(const Scene& scene);
  // The dynamic bodies that hang through joints from the world or a
  // kinematic body (a fixed base): Solver::kAuto's measure of "an arm".
  size_t AnchoredBodies() const;
  void TrackJointPositions();
  // The space holding the geoms of `instance` (the top-level space for -1).
  dSpaceID SpaceOf(int32_t instance);
  // ode_contacts.cc: the broadphase's candidate pairs (pairs_), in geom
  // build order.
  void FindCandidatePairs();
  static void NearCallback(void* data, dGeomID a, dGeomID b);
  void Collide(dGeomID a, dGeomID b);  // records a candidate pair
  void FindContacts();                 // dCollide per pair, concurrently
  void AddContacts(size_t pair);       // its contact joints

  Options options_;
  DynamicsSettings settings_;
  dWorldID world_ = nullptr;
  dSpaceID space_ = nullptr;
  dJointGroupID contacts_ = nullptr;
  dThreadingImplementationID threading_ = nullptr;
  std::unique_ptr<SolverThreads> solver_threads_;  // the solver's threads (CreateWorld), or null
  std::vector<DynamicBody> bodies_;
  std::vector<KinematicBody> kinematic_;
  std::vector<StaticGeom> static_geoms_;  // slot order; those that never moved
  std::vector<SimJoint> joints_;
  std::vector<SimForceSensor> force_sensors_;
  std::vector<std::unique_ptr<dJointFeedback>> feedback_;  // (force_sensors_), stable addresses
  std::vector<GeomInfo> geom_info_;                        // indexed by the geom's data (index + 1)
  std::vector<MovingSurface> surfaces_;                    // slot order
  // Each model instance's dSimpleSpace inside space_ (SpaceOf), or null.
  std::vector<dSpaceID> instance_spaces_;
  // A substep's candidate geom pairs (broadphase order) and their contact
  // points: pair k's in [k * ContactCapacity(), + count).
  struct CandidatePair {
    dGeomID a, b;    // a built before b
    int count;       // contact points (FindContacts)
    uint64_t order;  // a's build index, then b's: the pairs' order
  };
  std::vector<CandidatePair> pairs_;
  // Contact points a pair may keep: max_contacts, or more in a world with
  // meshes (their pairs spread them over the patch; ode_contacts.cc).
  int ContactCapacity() const;
  std::vector<dContactGeom> pair_contacts_;
  bool has_meshes_ = false;  // a trimesh geom: contacts on one thread (OPCODE)
  // Mesh assets in use and their trimesh data (ODE reads the asset's arrays in place).
  std::vector<std::pair<std::shared_ptr<const TriangleMesh>, dTriMeshDataID>> meshes_;
  // Index buffers of one-triangle meshes, doubled (MeshData); ODE points at them.
  std::vector<std::vector<MeshTriangle>> single_triangle_meshes_;
  // Joint commands, read once per control step (rows of joints_).
  std::vector<JointCommand> commands_;
  // Each joint's motor velocity this substep (ApplyMotors): a dependent
  // joint's feed-forward is its master's.
  std::vector<double> motor_velocity_;
  bool has_mounts_ = false;     // some force sensor hangs from a static shape (Build)
  bool exact_solver_ = false;   // dWorldStep (Options::solver, or auto by body count; Build)
  double step_dt_ = 0;          // substep length, for the servo
  uint64_t substeps_done_ = 0;  // seeds each substep's constraint shuffles
  bool broken_ = false;         // an ODE call was unwound by an error (Substep)
};

}  // namespace swarmsim::ode
