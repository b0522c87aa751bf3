// The planar contact backend (`physics: planar`): for swarms that only drive
// and bump (Kilombo's kinematic motion with overlap resolution, ARGoS's
// point-mass engine). No forces, masses or friction: a robot goes where its
// wheels roll it, and overlaps are undone by moving positions.
//
// What becomes what (Build), with box2d's conventions (box2d_backend.h):
//   - Each dynamic shape is a body at its world (x, y, yaw): cylinder,
//     capsule and sphere -> circle; box -> oriented rectangle of its x, y
//     extents; mesh -> the rectangle of its bounding box's x, y extents.
//   - Static shapes that are no part of a body and reach into the bodies'
//     height range, and the environment map's voxels there, are obstacles
//     projected to the plane: upright cylinders and spheres -> circles,
//     upright boxes -> oriented rectangles; tilted boxes, lying cylinders and
//     meshes -> the axis-aligned rectangle around their projection
//     (conservative: box2d takes the exact hull). Taken at Build. Belts are
//     not obstacles and carry nothing here.
//   - Wheels are found as in box2d (modules/dynamics/plane_wheels.h). A
//     wheeled body rolls without slip: its velocity (vx, vy, w) in its plane
//     frame is the least-squares solution of "each wheel's contact point moves
//     forward at its surface speed (target_velocity * R) and not sideways",
//     precomputed at Build as one column per wheel (two wheels of a
//     differential drive: exact). Motor force limits are ignored. A body
//     without wheels stays put unless pushed.
//
// A step (dt x physics_substeps seconds) is one advance:
//   1. Every wheeled body moves along its exact arc for the internal step
//      (constant commands over a step make the motion an arc; no need for
//      physics_substeps' small steps, which this backend does not use).
//   2. Overlaps are resolved by position projection, Jacobi style: in each
//      pass every body computes its correction from the previous iterate
//      only (against each other body it touches, its share of the overlap
//      by mass, m_other / (m_self + m_other): half for two equal robots, so
//      a 1.6 kg foot-bot pushing a 0.3 kg crate goes on at 84% of its wheel
//      speed; the sum averaged beyond two contacts so crowds do not
//      overshoot; all of the overlap against
//      each obstacle it touches, the obstacles swept twice for corners), and
//      all bodies move at once. At most Options::iterations passes (4); they
//      stop once no two bodies overlap by more than Options::tolerance
//      (0.1 mm). Contacts move centres only: nothing turns a body, no
//      friction, no restitution. Obstacles always win: a robot pressed into a
//      wall by a crowd ends outside the wall and may overlap the crowd.
//   Tunnelling: the step is cut into internal steps so that no body moves
//   more than Options::max_move_fraction (1/4) of its inner radius (circle:
//   radius; rectangle: smaller half extent) in one. A body entering anything
//   by less than its inner radius still has its centre on the near side of
//   the other's middle, so it is pushed back out the side it came in: no
//   thin wall is crossed at any speed (at a cost of more internal steps for
//   fast robots; at most Options::max_internal_steps).
//
// Broad phase: Verlet lists. Each body keeps the bodies and obstacles within
// its bounding radius + a skin (the mean bounding radius) of it,
// queried from framework/spatial_grid.h; the lists are rebuilt when some body
// has moved more than half the skin since. Contacts are computed exactly from
// the lists, in ascending index, so results do not depend on when they were
// rebuilt.
//
// Parallel and deterministic: the rolling, the list queries, the Jacobi
// passes and the write-back are parallel over bodies on the world's workers
// (DynamicsSettings::scheduler); each body writes only its own row and reads
// the previous iterate; the only reductions are maxima. So the state is
// bit-identical for any thread count. The state the scene does not hold is
// each body's unwrapped yaw (folded by HashState with its position).
//
// Velocities written back are what moved over the step / its duration; wheel
// joint positions are advanced by World::Actuate, as with box2d.
#pragma once

#include <memory>

#include "framework/dynamics_backend.h"
#include "framework/registry.h"
#include "modules/dynamics/planar/planar_options.h"

namespace swarmsim {
class Scene;
}

namespace swarmsim::planar {

swarmsim::ModuleInfo ModuleInfo();
std::unique_ptr<DynamicsBackend> MakeBackend();

// The engine alone, for `swarmsim bench`'s `planar-only` row: builds the
// world from `scene`, reads the wheel commands once, then runs `steps`
// advances of dt x substeps with no scene write-back. Returns the seconds
// spent stepping.
double TimeBareLoop(const Scene& scene, double dt, int substeps, int steps, const Options& options,
                    const DynamicsSettings& settings);

}  // namespace swarmsim::planar
