// ODE 0.16 (double precision) dynamics: 3D rigid bodies, joints and contacts.
//
// What becomes what (Build, in scene slot order):
//   - Each dynamic shape (ShapeData::dynamic) is an ODE body at its world
//     pose with the shape's mass and the solid shape's inertia, and one geom
//     (box, sphere, cylinder or capsule; ODE's axes match ours: z is the
//     cylinder/capsule axis).
//   - A non-dynamic shape whose nearest dynamic ancestor is reached without
//     crossing a joint is a *part* of that body: an extra geom at its offset,
//     adding no mass.
//   - Any other non-dynamic shape inside a model, or below a joint, is a
//     *kinematic* body: scripts, IK or kinematic joints move it in the scene
//     and the backend pushes that motion into ODE each step (pose
//     interpolated over the substeps, velocity from the pose change), so
//     dynamic bodies collide with it as with a moving, unstoppable object.
//   - Other non-dynamic shapes (walls, tables, floor slabs outside models) are
//     static geoms, placed at Build time.
//   - With Options::ground_plane, the plane z = 0 is a static geom.
//   - The scene's environment map (framework/environment.h): its voxels that
//     reach more than 1 mm into the height range of the dynamic shapes at
//     Build (a floor under the robots and a ceiling above them do not),
//     merged into boxes (environment_obstacles.h), are static box geoms
//     (friction 0.7, no restitution).
//   - A joint J whose subtree holds a dynamic shape B, reached without
//     crossing another joint, is an ODE joint between B and J's nearest
//     dynamic (or kinematic) ancestor body A, or the static world if there is
//     none: revolute -> hinge, prismatic -> slider, both along J's z axis;
//     spherical -> ball; fixed -> fixed. Such joints are *simulated*
//     (JointData::simulated): ODE integrates their position and velocity and
//     World::Actuate leaves them alone. Joints with no dynamic child stay
//     kinematic (moved by World::Actuate). Modes: passive (free, limits
//     only), velocity (motor to target_velocity with max_force), position
//     (servo: motor velocity 0.5 error / dt clamped to max_velocity, with
//     max_force), force (target_force applied each substep). A dependent
//     joint (JointSettings::depends, a URDF mimic) whose master ODE simulates
//     is servoed every substep to offset + factor * the master's position, at
//     factor * the master's motor speed plus a correction. Limits
//     (min/max_position) become ODE stops, with their own ERP and CFM (the
//     joint's limit_erp/limit_cfm, else Options::limit_erp/limit_cfm, else
//     erp/cfm) and a fudge factor of 0 (no jump when a motor drives a joint
//     away from its stop). Revolute positions are unwrapped (a wheel's angle
//     keeps growing).
//
// Solver (Options::solver, the world's `simulation.ode`): dWorldStep (exact)
// or dWorldQuickStep (iterative); `auto` takes the exact one for worlds of at
// most kExactSolverBodies dynamic bodies at Build, two thirds of them
// hanging from a fixed base (an arm holds its commanded configuration to
// the joints' CFM under load, 3e-6 m for the Panda), quickstep above
// (swarms: the solver is the cost) and for floating robots and free bodies
// in contact (the exact solve's LCP degenerates there).
//
// Contacts: up to Options::max_contacts per geom pair, friction the geometric
// mean of the two shapes' (pyramid approximation), restitution the larger of
// the two (above 0.1 m/s). No contacts between geoms of one model instance
// (no self-collision), between geoms of one body, between bodies joined by a
// joint, or between two non-dynamic geoms.
//
// Moving surfaces (ShapeData::surface_velocity and surface_angular_velocity:
// conveyor belts, modules/paths): a contact with such a geom gets a first
// friction direction along the surfaces' relative velocity at the contact
// point, projected into the contact plane, and that speed as its contact
// motion (dContactMotion1), so friction carries the other body along. The
// geoms are listed at Build; their velocities are read every step.
//
// Hybrid simulation: Scene::SetShapeDynamic (sim.setObjectDynamic) is a
// structural change; the backend then rebuilds from the scene, velocities
// included. A script that sets a dynamic body's pose teleports it.
//
// Spaces. Each robot (model instance) has its own dSimpleSpace holding all
// its geoms; a sweep-and-prune space holds these sub-spaces and every geom
// outside a robot (statics, loose dynamic objects, the environment map's
// boxes, the ground plane). A robot's geoms are never paired with each other
// (no self-collision), so its sub-space is only tested against others:
// broadphase cost and memory grow with the robot count (ODE's hash space,
// used before, keeps an n x n bit table of tested pairs: 10,000 hexapods
// ended in an ODE assertion after 8.6 GB).
//
// Threads and determinism. A substep finds the candidate geom pairs on the
// calling thread, puts them in the geoms' build order (the spaces' own order
// depends on the order the solver last moved the geoms), computes every
// pair's contact points concurrently on the world's workers
// (DynamicsSettings::scheduler; each pair writes only its own slots), then
// creates the contact joints in pair order. The solver then steps ODE's
// islands (bodies linked by joints and contacts: a robot, or robots touching)
// concurrently on the run's threads, each island by ODE's single-threaded
// quickstep on one thread, through our own ODE threading implementation
// (ode_threading.h: why not ODE's pool, and how an island gets one thread).
// Quickstep shuffles an island's rows with dRandInt, ODE's process-global
// random generator; the program defines its own dRandInt (ode_world.cc),
// whose draws come from a stream that starts at the substep's seed for every
// island, so they do not depend on which thread solves which island when.
// Both are checked once per process, and `swarmsim modules` says how the
// solver runs. The state is bit-identical for any thread count, 1 included.
// Each backend owns its ODE world and its solver threads. Meshes: Debian's
// ODE trimesh collision (OPCODE) is not thread-safe, so a world with a mesh
// finds its contact points on the calling thread.
//
// Meshes. A mesh shape is a dTriMesh geom; its trimesh data is made once per
// asset per world and reads the shared asset's arrays in place. A dynamic
// mesh's mass sits at the shape's origin, with its bounding box's inertia
// about that origin (ode_world.cc, CalcMass).
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "modules/dynamics/ode/ode_options.h"

namespace swarmsim {
class Scene;
}

namespace swarmsim::ode {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<DynamicsBackend> MakeBackend();
std::unique_ptr<DynamicsBackend> MakeBackend(const Options& options);
// The world file's `simulation.ode` mapping: its keys and reader
// (ode_section.cc), registered beside the backend (modules/builtin.cc).
DynamicsSection Section();

// ODE alone, for the bench's `ode-only` row: builds the same ODE world from
// `scene`, reads the joint commands once, then runs steps x substeps ODE
// steps of `dt` (collision + solver) with no scene write-back. Returns the
// wall-clock seconds spent stepping.
double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps,
                    const Options& options = {}, const DynamicsSettings& settings = {});

}  // namespace swarmsim::ode
