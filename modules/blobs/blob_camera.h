// The `blob_camera` object type's row: a camera that sees the lit LEDs of
// other robots (leds.h) without rasterising (ARGoS's colored blob
// omnidirectional / perspective camera). Each sense phase fills `blobs`:
// the LEDs within `range` of the camera's origin and inside its field of
// view, not hidden by a shape, with their colour, distance, bearing and
// elevation in the camera's frame. Public for tests and for code that
// compares it with a rendered camera; scripts use sim.readBlobCamera.
#pragma once

#include <vector>

#include "framework/handle.h"
#include "framework/math.h"

namespace swarmsim {

inline constexpr const char* kBlobCameraTypeName = "blob_camera";

// One LED as a camera sees it.
struct Blob {        // 56 bytes
  Vec3 color;        // the LED's RGB
  double distance;   // m, camera origin to the LED's centre
  double bearing;    // rad, in (-pi, pi]: angle of the LED's direction in the camera's xy
                     // plane from its +x axis, counter-clockwise (about +z)
  double elevation;  // rad, in [-pi/2, pi/2]: angle above the camera's xy plane
  ObjectId led;      // the LED object
};

struct BlobCameraRow {
  // Settings.
  double range = 1.0;                       // m, > 0
  double fov = 6.283185307179586;           // rad: horizontal field of view about +x (2 pi: all
                                            // around)
  double vertical_fov = 3.141592653589793;  // rad: |elevation| <= vertical_fov / 2 (pi: all)
  bool occlusion = true;                    // shapes hide LEDs
  double angle_noise = 0;                   // rad: std dev of the noise on bearing and elevation
  double distance_noise = 0;                // std dev of the noise on distance, x distance
  double failure = 0;   // probability that the camera sees nothing in a step (sensor_noise.h)
  bool enabled = true;  // off: sees nothing
  // The reading, written in the sense phase: sorted by bearing, then
  // distance, then the LED's handle.
  std::vector<Blob> blobs;
};

}  // namespace swarmsim
