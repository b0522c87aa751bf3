// The Python binding's arrays of the devices beyond arrays.h (swarm/python/
// world.cc): vision-sensor images and depth, blob cameras, force sensors,
// distance and collision objects. One model's robots' devices of one type,
// found by type and name on each robot (ModelLayout, arrays.h).
#pragma once

#include <string>
#include <vector>

#include "swarm/python/arrays.h"

namespace swarmsim::python {

// The objects of type `type` ("vision_sensor") on each robot of `layout`,
// in hierarchy order, named as scripts index repeats (eye, cam[0], cam[1]).
struct DeviceTable {
  std::vector<std::string> names;
  std::vector<uint32_t> slots;  // robots x names
};
// Throws ValueError when the robots have different sets.
DeviceTable Devices(const Scene& scene, const ModelLayout& layout, const char* type);
// The column of `name` in `table` ("": the only one); ValueError naming the
// ones there are. what: "vision sensor".
size_t DeviceColumn(const DeviceTable& table, const std::string& name, const char* what);

// The vision sensors at `slots`: images (K, H, W, 3) uint8, rows top to
// bottom (the filter chain's when `filtered` and the sensor has one), or
// depth (K, H, W) float32 in metres along the view axis. Zeros before a
// sensor's first image. ValueError for sensors of different resolutions,
// or depth of a sensor with `depth: false`.
py::array VisionImages(const Scene& scene, const std::vector<uint32_t>& slots, bool filtered,
                       const py::object& out, const std::vector<std::string>& who);
py::array VisionDepths(const Scene& scene, const std::vector<uint32_t>& slots,
                       const py::object& out, const std::vector<std::string>& who);

// What the blob camera at slots[i] (one per robot) saw in the last sense
// phase, as flat arrays: robot i's blobs are rows offsets[i] to
// offsets[i + 1] - 1 (sorted by bearing): offsets (N + 1, int64), color
// (M x 3), distance (m), bearing, elevation (rad) (float64), robot (M,
// int64: the LED's robot, -1 for a LED of no robot).
py::dict BlobCameras(const Scene& scene, const std::vector<uint32_t>& slots);

// Force sensors, (N, sensors, 6): Fx, Fy, Fz (N), Tx, Ty, Tz (N m), parent on
// child in the sensor's frame, filtered as sim.readForceSensor's (without its
// read noise); NaN where the physics backend gives no reading.
Array ForceSensors(const Scene& scene, const DeviceTable& table, size_t robots,
                   const py::object& out);
// (N, sensors) bool: the link broke.
py::array ForceSensorsBroken(const Scene& scene, const DeviceTable& table, size_t robots);

// Every distance object of the scene, in scene order: names (paths), found
// (K, bool), distance (K, m; inf: nothing within the threshold), p1, p2
// (K x 3, the closest points, world frame).
py::dict Distances(const Scene& scene);
// Every collision object: names, colliding (K, bool), offsets (K + 1,
// int64) and points (M x 3, world frame: the contact points kept).
py::dict Collisions(const Scene& scene);

}  // namespace swarmsim::python
