// Detection volumes of proximity sensors (CoppeliaSim's cone, pyramid,
// cylinder and disc sensors): the nearest point of a shape's part inside a
// volume, exact for every primitive and for triangle meshes.
//
// The volumes, in the sensor frame S (all convex; `range` bounds the
// distance from the origin, a sphere, so it is a cut on the reading itself):
// - cone:     angle from +z <= angle (< 90 deg), z >= blind_zone;
// - pyramid:  |x| <= z tan(angle), |y| <= z tan(angle_y), z >= blind_zone;
// - cylinder: x^2 + y^2 <= radius^2, z >= blind_zone (>= 0);
// - disc:     |z| <= thickness / 2, |atan2(y, x)| <= angle (<= 90 deg),
//             x >= blind_zone (a flat sector about +x).
//
// The reading is min |p| over p in (shape solid) ∩ volume, with |p| <= range:
// the nearest point of the part of the shape inside the volume, which is on
// the shape's surface or, for a shape cut by the volume's side, on that side
// (inside the shape). Meshes are surfaces: each triangle is cut by the
// volume on its own.
//
// Method. Both sets are convex, so the answer is the projection of the
// origin onto their intersection.
// 1. Exact fast path: the shape's own nearest point to the origin (box clamp,
//    sphere, cylinder, capsule segment, triangle: Ericson 5.1.5) lies in the
//    volume: that is the answer. Its distance is also a lower bound that
//    skips shapes (and triangles) no nearer than the best found.
// 2. Otherwise one piece of the volume cuts the shape (usually). For each
//    piece the nearest point violates, solve the relaxation "shape ∩ that
//    piece" exactly: for a half-space n.x <= c (a pyramid's or disc's side,
//    the blind plane, a disc's face) the answer is P_shape(-lambda n) at the
//    root lambda of n.x(lambda) = c (the Lagrange dual of the one
//    constraint; monotone, solved by Illinois regula falsi to 1e-13 of the
//    scene's scale, a few dozen projections); for a cone's or cylinder's
//    side, through its tangent half-space at the answer's azimuth, found by
//    iterating azimuth <- azimuth of the half-space's answer. A relaxation's
//    answer that lies in the whole volume is the answer (it is the minimum
//    over a superset). A relaxation with no point means no detection.
// 3. Two half-spaces active (a pyramid's edge, a disc's corner, a side at
//    the blind plane): the same dual, nested (the outer root over the second
//    multiplier, each value an inner step-2 solve): ~12 us.
// 4. Else (a cone's or cylinder's side with a plane, or three pieces)
//    Dykstra's alternating projections onto the shape and each of the
//    volume's pieces (a second-order cone, half-spaces, an infinite
//    cylinder, a slab; each projection exact and closed-form) converge to
//    the projection of the origin onto the intersection. Iterations stop
//    when no projection or increment moves by 1e-12 of the scene's scale
//    (or after 20,000 sweeps); the point is accepted if it lies within 1e-9
//    (relative) of every set.
// Precision: within 1e-9 m at 1 m scale against the closed forms in
// tests/modules/proximity/volume_test.cc. Cost (bench/proximity_volume_bench,
// 2-core VM): a ray reading 0.37 us, a cone over four primitives 0.8 us
// when step 1 answers, 1.1 us when a side cuts the box (step 2); step 4
// takes ~1,000 sweeps (tens of microseconds). A shape whose bounding sphere
// misses a piece of the volume is skipped before any of this.
//
// The normal is the shape's outward normal at its surface point nearest the
// detected point (for a point inside a shape cut by the volume: the nearest
// face's). The reflectance cut-off compares it with the direction from the
// point back to the sensor; a shape whose nearest point fails it is not
// detected (its farther points are not searched).
//
// Internal to modules/proximity.
#pragma once

#include <cstdint>

#include "framework/math.h"
#include "framework/scene.h"
#include "modules/proximity/proximity_sensor.h"
#include "modules/proximity/ray_cast.h"

namespace swarmsim::proximity {

// A volume in its sensor's frame, ready for the queries below.
struct Volume {
  ProximityVolume kind = ProximityVolume::kCone;
  double range = 0;
  double cos_angle = 1, sin_angle = 0;  // cone, disc
  double cos_x = 1, sin_x = 0;          // pyramid, about x (the x extent)
  double cos_y = 1, sin_y = 0;          // pyramid, about y
  double radius = 0;                    // cylinder
  double half_thickness = 0;            // disc
  double blind_zone = 0;                // m
  double cos_max_detection_angle = -1;  // -1: no cut-off
  bool detect_front = true, detect_back = true;
};

Volume MakeVolume(const ProximitySensorData& sensor);

// A box (sensor frame) that holds the volume within `range` of the origin.
void VolumeBounds(const Volume& volume, Vec3* lo, Vec3* hi);

// Is p (sensor frame) in the volume, within `tolerance` m?
bool InVolume(const Volume& volume, const Vec3& p, double tolerance);

struct VolumeHit {
  double distance = 0;  // m
  Vec3 point;           // sensor frame
  Vec3 normal;          // sensor frame, unit
};

// The nearest point of (shape ∩ volume) if it is nearer than `best` (and
// within range), passes the cut-off and (meshes) the face filter: sets *hit.
// X_SW: the world in the sensor's frame.
bool NearestInVolume(const Volume& volume, const PlacedShape& shape, const Pose& X_SW, double best,
                     VolumeHit* hit);

// The outward normal (world frame, unit) of the shape at its surface point
// nearest p_W. Meshes: the normal of the nearest triangle.
Vec3 SurfaceNormal(const PlacedShape& shape, const Vec3& p_W);

// `count` random directions in the cone of half-angle `angle` about +z,
// uniform over the spherical cap, from stream `stream` of `seed` (the
// caller keys it by sensor and step: the same whatever thread reads it).
void RandomRayDirections(uint64_t seed, uint64_t stream, double angle, uint32_t count, Vec3* out);

}  // namespace swarmsim::proximity
