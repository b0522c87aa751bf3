// Box2D 2.4 dynamics: a top-down plane of robots and obstacles.
//
// What becomes what (Build):
//   - Each dynamic shape (ShapeData::dynamic) is a b2_dynamicBody at its world
//     (x, y, yaw): cylinder and sphere -> circle, box -> rectangle of its x, y
//     extents. Its mass is ShapeData::mass exactly; its inertia about the
//     vertical axis is the real shape's (cylinder m r^2/2, sphere 2 m r^2/5,
//     box m (x^2 + y^2)/12). Bodies are created in scene slot order.
//   - Non-dynamic shapes below a dynamic shape are parts of it (wheels,
//     decorations) and get no fixture. Every other non-dynamic shape
//     (walls, obstacles) is a fixture of one static ground body, projected to
//     the plane, if its height range overlaps the dynamic shapes' height range
//     (so a floor slab under the robots is not an obstacle). Static fixtures
//     are taken at Build time; moving a static shape afterwards does not move
//     its fixture.
//   - The scene's environment map (framework/environment.h): its voxels that
//     reach into the same height range, projected to the plane and merged
//     into rectangles (environment_obstacles.h), are fixtures of the ground
//     body too (default material: friction 0.7, no restitution).
//   - A *wheel* is a revolute joint in velocity mode whose nearest dynamic
//     ancestor is a body, whose z axis (the rotation axis) is horizontal in
//     that body's plane frame, and that has a non-dynamic cylinder or sphere
//     child giving the wheel radius R. Bodies with no wheel get ground
//     friction instead (a b2FrictionJoint to the ground with max force
//     mu m g and max torque 2/3 mu m g r, r the footprint radius).
//
//   - Moving surfaces (ShapeData::surface_velocity: conveyor belts) that are
//     no part of a body are belts, not obstacles: a body without wheels lying
//     on one (centre over its footprint, bottom at its top) has its ground
//     friction pull it towards the belt's surface velocity and turn instead
//     (plane_belts.cc).
//
// Wheel sign convention. A revolute joint turns its children by +theta about
// its own z axis `a` (right-hand rule). The contact point sits at -R below
// the wheel centre, so rolling without slip needs
//   v_centre = -(theta_dot a) x (-R up) = theta_dot R (a x up).
// The wheel therefore drives along forward = a x up with surface speed
// target_velocity * R: a wheel whose axis points +y in the body drives the body
// towards +x for a positive velocity. A mirror-mounted right wheel (axis -y)
// needs a negative velocity to drive forward.
//
// Traction model (no wheel bodies: a few flops per wheel and substep). Before
// each Box2D step, for each wheeled body, an impulse at each wheel's contact
// point (the wheel centre in the plane) removes the error between the point's
// velocity and the desired one (surface speed along forward, zero sideways),
// using the 2x2 effective mass at that point. The accumulated impulse of each
// wheel is clamped to the Coulomb limit mu (m g / n_wheels) dt (mu: the wheel
// shape's friction) and its forward part to the motor limit
// (JointData::max_force / R) dt. The wheels of a body are solved together by
// Options::traction_iterations projected Gauss-Seidel passes. Saturated
// traction lets robots push each other and slide along walls; a blocked robot
// gains no energy, as traction only removes velocity error and contacts
// remove the rest.
//   Warm start: the velocity change that contacts made in the last step,
// projected on each wheel's forward direction, is added to that wheel's
// error. Without it, a robot pushing an object runs one step of contact
// impulse behind its command (pushing a 0.5 kg puck at 5 cm/s with 10 ms
// steps it moved at 3.5 cm/s). Only the forward part: sideways, the same
// feedback keeps adding a wall's push-back to the error and a saturated wheel
// then has no grip left to slide along the wall with.
//   Known behaviour: driven into a wall of friction 0.1 or more at more than
// about 15 degrees to it, a round robot is turned by the contact friction to
// face the wall and stops there; at shallower angles, or on a frictionless
// wall, it slides along (on a frictionless wall at 45 degrees, about 30%
// faster than ideal Coulomb friction would let it; within 4% below 15).
//   A robot with a nonzero wheel command is kept awake; an idle one may sleep.
//
// Length scale. Box2D 2.4 is tuned for objects of 0.1 to 10 units and has
// fixed margins in its own units, compiled into the Debian library:
// b2_linearSlop 0.005 (penetration left uncorrected), b2_polygonRadius 0.01
// (skin around polygons), b2_aabbExtension 0.1 (broad-phase fattening),
// b2_maxTranslation 2 per step, sleep tolerance 0.01/s. For 3 to 10 cm robots
// in metres, 5 mm of penetration and a 1 cm skin are large. So internally one
// Box2D unit is 1/length_scale metres (default 0.1 m: lengths and velocities
// x10). Masses stay in kg (densities are adjusted), so forces and impulses
// scale by length_scale, torques and inertias by length_scale^2. Then the
// slop is 0.5 mm (a robot hitting a wall at 0.5 m/s ends 0.5 mm into it
// instead of 4.2 mm), the fat-AABB margin 1 cm, the speed cap 20 m/s at 10 ms
// steps, sleep below 1 mm/s. Box and ground-box polygons are also shrunk by
// the polygon skin so that their collision surface is the real face (else
// walls would stand 1 mm proud at scale 10, 1 cm at scale 1). Restitution
// applies above 0.1 m/s whatever the scale. Scaling does not change float
// precision in metres: 100 m from the origin a position resolves ~8 um.
//
// Partitions (simulation.physics_partitions, DynamicsSettings::partitions;
// plane_partition.h). With N > 1 the plane is cut into N strips across the
// longer side of the bodies' bounding box at Build, borders placed so that
// each strip holds the same number of body centres then (fixed until the
// next rebuild; from the scene only, never from the thread count); past 16
// regions the strips are columns, each cut the same way into rows (near-square
// regions). Each region is its own Box2D world with the traction model above,
// owning the bodies whose centre lies in it. `auto` (0): one region per 250
// bodies, at most 1,024 (under 500 bodies: one world). A world with belts or
// force sensors stays one world (riders and welds are not split).
//   - Static geometry (walls, obstacles, map voxels) is copied into every
//     strip it reaches, widened by 1 m plus four of the largest body's radius:
//     a wall across all strips is solid in each.
//   - Ghosts: once per control step, after migration, each body within reach
//     of another strip (its bounding radius + the largest body's + 1.5 x its
//     speed bound x the step's duration + Box2D's AABB margin; the speed bound
//     is its speed or its wheels' commanded surface speed, whichever is
//     larger) gets a ghost there: a kinematic body with its fixtures. Before
//     every substep each ghost takes its owner's pose and velocity as
//     published after the previous substep (double-buffered by slot), and
//     moves with that velocity during the substep. A ghost has infinite mass:
//     two robots meeting on a border each see the other as a wall moving at
//     its own velocity (they stop each other as in one world; momentum across
//     a border is not exchanged exactly), and a robot pushing a crate across
//     a border drives it through its ghost.
//   - Migration: before each step's substeps (after scripts may have moved
//     bodies), a body whose centre left its strip is moved to the strip
//     holding it: re-created with the same fixtures, mass, pose (unwrapped
//     angle), velocity, awake flag, wheels and ground friction, appended to
//     that strip's bodies; in strip order then body order. Its contact warm
//     starts and sleep timer start afresh.
//   - Substeps: strips step concurrently (DynamicsSettings::scheduler,
//     ParallelFor over strips); each reads only the published states and
//     writes only its own bodies and its own slots of the next states, so
//     which worker steps which strip never changes a bit. Everything between
//     substeps (migration, ghost sets, write-back) runs on the caller in a
//     fixed order.
//   - HashState folds the strip count and, per strip in order, its body count
//     and its state as below (contacts with ghosts included). One partition is
//     exactly one world: the same hashes as before partitions existed.
//   - Cost: bodies near borders are simulated twice (once as a ghost), and
//     there is a barrier per substep. Measured on diffusion in worlds/README.md
//     ("Physics partitions").
//
// Determinism. Box2D runs on one thread in a fixed order per world; the world
// is built in slot order, so the same scene and steps give bit-identical
// results.
// Engine state that the scene does not mirror (float positions and unwrapped
// angles, velocities, awake flags, contact warm-start impulses, friction
// joint impulses) is folded by HashState.
//
// The backend rebuilds its world if the scene's structure changes (objects
// added or removed), taking body velocities from the scene; and it moves a
// body whose pose was set from outside (a script teleporting a robot). It
// writes body poses and velocities only: wheel joint positions are advanced by
// World::Actuate, which integrates every velocity-mode joint.
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "modules/dynamics/box2d/box2d_options.h"

namespace swarmsim {
class Scene;
}

namespace swarmsim::box2d {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<DynamicsBackend> MakeBackend();
std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options);

// Box2D alone, for the scaling bench's `box2d-only` row: builds the same
// Box2D world from `scene` with the same body and wheel code as the backend,
// reads the wheel commands once, then runs steps x substeps Box2D steps of
// `dt` with the same traction model, but with no scene write-back and no
// framework calls. Returns the wall-clock seconds spent stepping (not
// building).
double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps,
                    const Options& options = {}, const DynamicsSettings& settings = {});

}  // namespace swarmsim::box2d
