// The Box2D world behind the box2d backend: the scene projected to the plane,
// plus the wheel traction model. Shared by the backend and TimeBareLoop so
// that both do the same physics work. Internal: Box2D types stay in this
// folder (see box2d_backend.h for the model and the units).
#pragma once

#include <box2d/b2_world.h>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/math.h"
#include "modules/dynamics/box2d/box2d_options.h"
#include "modules/dynamics/height_range.h"
#include "modules/dynamics/obstacle_poses.h"

namespace swarmsim {
class Scene;
class StateHasher;
struct JointData;
struct ShapeData;
}  // namespace swarmsim

class b2FrictionJoint;

namespace swarmsim::dynamics {
struct PlaneWheelGeometry;
}

namespace swarmsim::box2d {

// One simulated body: a dynamic shape.
struct PlaneBody {  // 64 bytes
  b2Body* body = nullptr;
  uint32_t slot = 0;         // scene slot of the dynamic shape
  uint32_t first_wheel = 0;  // wheels_[first_wheel, first_wheel + wheel_count)
  uint32_t wheel_count = 0;
  bool commanded = false;  // some wheel has a nonzero command this step
  // Box2D units, fixed at Build (not divided out again every substep).
  double inverse_mass = 0, inverse_inertia = 0;
  // Wheeled bodies: velocity after the traction impulses, and the change the
  // Box2D step (contacts) made to it, world frame, Box2D units. The next
  // traction solve aims at the velocity *after* that change (a warm start), so
  // a robot pushing an object keeps its speed instead of lagging one step's
  // contact impulse behind.
  b2Vec2 v_traction{0, 0};
  float w_traction = 0;
  float dv_x = 0, dv_y = 0, dw = 0;
};

// What the scene does not hold about a body: the part of its pose the plane
// does not simulate, and the pose last written (to notice teleports).
struct PlaneBodyPose {  // 104 bytes
  double z = 0;         // m, kept
  Quat q_tilt;          // roll and pitch, kept: q_WB = FromYaw(yaw) * q_tilt
  Pose X_WB_last;       // pose last written to (or read from) the scene
  // Box2D rotation (sin, cos) that X_WB_last.q was computed from; NaN when
  // X_WB_last was read from the scene instead (at Build, after a teleport).
  float rot_s = std::numeric_limits<float>::quiet_NaN();
  float rot_c = std::numeric_limits<float>::quiet_NaN();
};

// A wheel driving a body; everything in Box2D units and the body's plane
// frame (origin at the body's centre, x along its heading).
struct PlaneWheel {                     // 120 bytes
  uint32_t body = 0;                    // index into bodies
  uint32_t joint_slot = 0;              // scene slot of the revolute joint
  double p_x = 0, p_y = 0;              // contact point
  double f_x = 0, f_y = 0;              // unit forward direction (axis x up)
  double k_xx = 0, k_xy = 0, k_yy = 0;  // inverse of the 2x2 effective mass at p
  double radius_m = 0;                  // wheel radius, m
  double coulomb_rate = 0;              // mu m g / n_wheels (impulse per second)
  double motor_rate = 0;                // max_force / R (impulse per second)
  double surface_speed = 0;             // command: target_velocity * R, units/s
  double lag = 0;                       // contact velocity change along forward, last step
  double acc_x = 0, acc_y = 0;          // impulse accumulated in the current substep
};

// A wheeled body's traction solve in progress (PlaneWorld::ApplyTraction).
struct TractionSolve {      // 64 bytes
  uint32_t body = 0;        // index into bodies
  bool converged = false;   // its last pass changed no impulse
  double c = 1, s = 0;      // heading: cos, sin
  double inverse_mass = 0;  // Box2D units
  double inverse_inertia = 0;
  double vx = 0, vy = 0, w = 0;  // velocity, body plane frame, Box2D units
};

// A moving surface (ShapeData::surface_velocity: a conveyor belt's
// segment) that is no part of a body: its footprint in the plane and its
// top, taken at Build (like static obstacles); its surface velocity read
// every step. Box2D units but `top`.
struct PlaneBelt {  // 88 bytes
  uint32_t slot = 0;
  double c_x = 0, c_y = 0;        // footprint centre
  double cos = 1, sin = 0;        // footprint rotation (the shape's yaw)
  double half_x = 0, half_y = 0;  // footprint half extents
  double top = 0;                 // m, height of its top face
  double friction = 0;            // the belt's Coulomb coefficient
  double v_x = 0, v_y = 0;        // surface velocity at the centre, world frame
  double w = 0;                   // rad/s: the surface's turn about the vertical
};

// A body without wheels that may lie on a belt (only built when there are
// belts): what its ground friction is while it does.
struct PlaneRider {                     // 48 bytes
  uint32_t body = 0;                    // index into bodies_
  int32_t belt = -1;                    // the belt it lies on in this substep, or -1
  double bottom = 0;                    // m, height of its lowest point (z stays put in the plane)
  b2FrictionJoint* friction = nullptr;  // its ground friction, off while on a belt
  double max_force = 0;                 // the joint's own force limit, Box2D units
  double max_torque = 0;                // and torque limit
  double body_friction = 0;             // its shape's Coulomb coefficient
};

using dynamics::HeightRange;  // height range [lo, hi] of shapes, m

// A body's Box2D state as a region publishes it for the ghosts of it in
// other regions (plane_partition.h). Box2D units; indexed by scene slot.
struct PlaneBodyState {  // 28 bytes
  float x = 0, y = 0, angle = 0;
  float vx = 0, vy = 0, w = 0;
  bool awake = false;
};

// A body of another region mirrored here (a kinematic body following it).
struct PlaneGhost {
  uint32_t slot = 0;  // the owner's scene slot
  b2Body* body = nullptr;
};

class PlaneWorld {
 public:
  // For EngineBackend (engine_backend.h), which runs the step below.
  using Options = box2d::Options;
  static constexpr std::string_view kName = "box2d";
  static constexpr bool kIdleWithoutSubsteps = false;

  PlaneWorld(const Options& options, const DynamicsSettings& settings);
  ~PlaneWorld();
  PlaneWorld(const PlaneWorld&) = delete;
  PlaneWorld& operator=(const PlaneWorld&) = delete;

  // Builds bodies, ground fixtures, wheels and ground friction from the scene
  // (discarding any previous world). Body velocities come from the scene.
  void Build(const Scene& scene);
  // No joint is simulated: wheels drive by traction and World::Actuate
  // advances their positions.
  void MarkJoints(Scene* /*scene*/) const {}
  // Moves bodies whose scene pose differs from the last one written (set from
  // outside since the last step).
  void SyncFromScene(const Scene& scene, double /*duration*/);
  // Reads each wheel's target velocity from its joint.
  void ReadCommands(const Scene& scene);
  // One Box2D step of dt seconds: traction impulses, b2World::Step, then the
  // contact-made velocity change of each wheeled body.
  void Substep(double dt, double /*fraction*/);
  // Writes body poses and velocities. Wheel joint positions are not written:
  // World::Actuate already advances every velocity-mode joint kinematically.
  void WriteBack(Scene* scene);
  void Hash(StateHasher* hasher) const;

  int body_count() const { return static_cast<int>(bodies_.size()); }
  int wheel_count() const { return static_cast<int>(wheels_.size()); }

  // Regions (plane_partition.h drives them; plane_world_regions.cc).
  // A world with only its ground body (no scene).
  void BuildEmpty() { Reset(); }
  // False when the world has what a region cannot split: belts (riders'
  // friction is per belt) or force sensors (welds between bodies).
  bool CanPartition() const { return belts_.empty() && force_sensors_.empty(); }
  const std::vector<PlaneBody>& bodies() const { return bodies_; }
  // The scene shapes Build made ground fixtures of, and their poses then;
  // the dynamic shapes' height range.
  const dynamics::ObstaclePoses& obstacle_poses() const { return obstacle_poses_; }
  const HeightRange& dynamic_range() const { return dynamic_range_; }
  // Static shapes that moved (PartitionedPlaneWorld::SyncFromScene): adds
  // their ground fixtures where they are now (those in `dynamic_range`), to
  // a world made by BuildEmpty, to be copied into the regions; and drops a
  // region's fixtures of the shapes at `slots` (ascending).
  void AddShapeObstacles(const Scene& scene, std::span<const uint32_t> slots,
                         const HeightRange& dynamic_range);
  void RemoveShapeObstacles(std::span<const uint32_t> slots);
  // Adds to this world's ground the ground fixtures of `from` whose AABB
  // reaches into [lo, hi] along `axis` (0: x, 1: y) and [cross_lo, cross_hi]
  // along the other axis, Box2D units.
  // The bodies that fixtures copied there may overlap are woken (a sleeping
  // body does not notice a new static fixture).
  void CopyGround(const PlaneWorld& from, int axis, double lo, double hi, double cross_lo,
                  double cross_hi);
  // Moves body `b` with its wheels, ground friction, pose record, velocity
  // and awake state to the end of `to`'s bodies, leaving a hole here that
  // Compact() closes. Contact warm starts of the body are lost.
  void MoveBody(uint32_t b, PlaneWorld* to);
  // The same copy into `to`, leaving this world's body as it is: for a world
  // about to be destroyed whole (the partitions' staging world at Build),
  // where destroying each body is quadratic (Box2D 2.4's DestroyProxy scans
  // every proxy moved since the last step).
  void CopyBody(uint32_t b, PlaneWorld* to) const;
  // Drops moved bodies, keeping the others in order.
  void Compact();
  // The largest speed the body may reach in this step, Box2D units/s: its
  // speed or its wheels' commanded surface speed.
  double SpeedBound(uint32_t b) const;
  // Bounding radius of a body's fixtures about its origin, Box2D units.
  static double BoundingRadius(const b2Body* body);
  // Makes the ghosts exactly `wanted` (slot, owner body), sorted by slot:
  // keeps those already there, destroys the others, creates the new ones.
  void SetGhosts(const std::vector<std::pair<uint32_t, const b2Body*>>& wanted);
  // Moves every ghost to its owner's published state,
  // states[state_of_slot[slot]].
  void RefreshGhosts(const PlaneBodyState* states, const uint32_t* state_of_slot);
  // Publishes every body's state at states[state_of_slot[slot]].
  void PublishStates(PlaneBodyState* states, const uint32_t* state_of_slot) const;
  int ghost_count() const { return static_cast<int>(ghosts_.size()); }

 private:
  // Build's phases, in order. 0: a fresh b2World and its ground body.
  void Reset();
  // 1. A body per dynamic shape, in slot order; fills body_of (slots) and
  // returns the dynamic shapes' height range.
  HeightRange BuildBodies(const Scene& scene, std::vector<int32_t>* body_of);
  void AddBody(const Scene& scene, uint32_t slot, const ShapeData& shape, const Pose& X_WS);
  // 2. Ground fixtures for the non-dynamic shapes that are no part of a body
  // and reach into the dynamic range, and for the environment map's voxels
  // that do.
  void BuildObstacles(const Scene& scene, const std::vector<int32_t>& body_of,
                      const HeightRange& dynamic_range);
  // `tag` (the fixtures' user data): the shape's slot + 1, 0 for map voxels.
  void AddObstacle(const ShapeData& shape, const Pose& X_WS, uintptr_t tag = 0);
  // 3. Wheels, grouped by body, each with its share of the body's weight.
  void BuildWheels(const Scene& scene, const std::vector<int32_t>& body_of);
  void AddWheel(uint32_t joint_slot, const JointData& joint, uint32_t body_index,
                const dynamics::PlaneWheelGeometry& geometry);
  // 4. A ground friction joint for every body without wheels.
  void BuildGroundFriction(const Scene& scene);
  // 2b. The belts, and (after 4.) the bodies that may ride them
  // (plane_belts.cc).
  void BuildBelts(const Scene& scene, const std::vector<int32_t>& body_of);
  void AddRider(const Scene& scene, uint32_t body, b2FrictionJoint* friction, double max_force,
                double max_torque);
  // Each belt's surface velocity, once per step.
  void ReadBelts(const Scene& scene);
  // Friction towards its belt's surface velocity for each body lying on a
  // belt (Coulomb-limited impulses before the Box2D step), in place of its
  // ground friction.
  void ApplyBelts(double dt);

  // Traction impulses for every awake wheeled body, in blocks of
  // kTractionBlock bodies (the second form does one block).
  void ApplyTraction(double dt);
  void ApplyTraction(std::span<const uint32_t> wheeled, double dt);
  // Weld joints for the scene's force sensors (plane_force_sensors.cc).
  void BuildForceSensors(const Scene& scene, const std::vector<int32_t>& body_of);
  // Samples each weld's reaction and breaks links over their threshold.
  void ReadForceSensors(Scene* scene);

  Options options_;
  DynamicsSettings settings_;
  double scale_;  // Box2D units per metre
  std::unique_ptr<b2World> world_;
  b2Body* ground_ = nullptr;
  dynamics::ObstaclePoses obstacle_poses_;  // the shapes behind ground_'s fixtures
  HeightRange dynamic_range_{0, 0};         // of the bodies, at Build
  std::vector<PlaneBody> bodies_;           // (bodies), slot order
  std::vector<PlaneBodyPose> body_poses_;   // (bodies)
  std::vector<uint32_t> wheeled_;           // bodies with wheels, ascending
  std::vector<PlaneWheel> wheels_;          // (wheels), grouped by body
  std::vector<PlaneBelt> belts_;            // slot order
  std::vector<PlaneRider> riders_;          // bodies without wheels, when there are belts
  static constexpr size_t kTractionBlock = 64;
  std::array<TractionSolve, kTractionBlock> traction_;  // ApplyTraction scratch, one block
  // Force sensors: weld joint (null once broken), scene row, sensor slot.
  struct PlaneForceSensor {
    b2Joint* weld;
    uint32_t row;
    uint32_t slot;
  };
  std::vector<PlaneForceSensor> force_sensors_;
  double last_dt_ = 0;              // s, of the last substep (for reaction forces)
  std::vector<PlaneGhost> ghosts_;  // sorted by slot
};

}  // namespace swarmsim::box2d
