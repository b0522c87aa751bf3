// The Python binding's arrays (read by swarm/python/world.cc and
// controller.cc): one model's robots laid out by slot, and the numpy arrays
// gathered from them (poses, velocities, proximity and light readings,
// joints), written into `out=` when given.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

#include "framework/world.h"

namespace swarmsim::python {

namespace py = pybind11;
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Slots of one model's robots' joints and proximity sensors, in the model's
// hierarchy order, rebuilt when robots are copied or removed.
struct ModelLayout {
  std::string model;
  std::vector<int> robots;                // instance indices, alive, ascending
  std::vector<std::string> joint_names;   // per robot, hierarchy order
  std::vector<std::string> sensor_names;  // proximity sensors, hierarchy order
  std::vector<uint32_t> root_slots;       // per robot
  std::vector<uint32_t> joint_slots;      // robots x joints
  std::vector<uint32_t> sensor_slots;     // robots x sensors
  std::vector<uint32_t> board_slots;  // per robot: its first range-and-bearing board, or kNoBoard
  static constexpr uint32_t kNoBoard = UINT32_MAX;
  std::vector<std::string> ground_names;  // ground sensors, hierarchy order
  std::vector<uint32_t> ground_slots;     // robots x ground sensors
  std::vector<std::string> light_names;   // light sensors (modules/light), hierarchy order
  std::vector<uint32_t> light_slots;      // robots x light sensors
  int64_t robot_count = -1;               // World::robot_count() it was built at
};

// Names that repeat within a robot (a proximity ring's `prox`) get the index
// scripts use: prox[0], prox[1], ...
void IndexRepeats(std::vector<std::string>* names);

// Rebuilds `layout` for `model` ("" : every robot) if robots came or went.
void Refresh(const World& world, const std::string& model, ModelLayout* layout);

// An output array of `shape`: `out` if it is one (float64, C-contiguous,
// writeable, that shape), else a new one.
Array OutArray(std::vector<py::ssize_t> shape, const py::object& out);
// Throws ValueError unless `out` is a plain numpy.ndarray (not a subclass
// such as a masked array) of `dtype` and `shape`, writeable and C-contiguous.
void CheckOut(const py::object& out, const py::dtype& dtype, const std::vector<py::ssize_t>& shape);

// Message bytes given from Python (range-and-bearing data, IR messages) as
// int64: integers, or floats that are whole numbers 0..255 (np.zeros makes
// floats); booleans and other dtypes are a TypeError, a fraction or a float
// outside 0..255 a ValueError. `what` starts the messages ("IR messages").
// The caller checks the shape and the integers' range.
py::array_t<int64_t, py::array::c_style> MessageBytes(const py::object& data,
                                                      const std::string& what);

// Poses of the layout's robots' roots: N x 3 (x, y, yaw) or N x 7 (x, y, z,
// qw, qx, qy, qz).
Array Poses(World& world, const ModelLayout& layout, bool planar, const py::object& out);

Array Velocities(const Scene& scene, const ModelLayout& layout, const py::object& out);

// Proximity readings, N x sensors: the distance to what each sensor sees,
// +inf where it sees nothing.
Array Proximity(const Scene& scene, const ModelLayout& layout, const py::object& out);
// N x sensors: each sensor's value on its response curve (`response:`; the
// far end where it sees nothing), NaN for a sensor without one.
Array ProximityValues(const Scene& scene, const ModelLayout& layout, const py::object& out);

// What each robot's first range-and-bearing board heard in the last sense
// phase, as flat arrays: robot i's readings are rows offsets[i] to
// offsets[i + 1] - 1 (nearest first; none for a robot without a board):
// offsets (N + 1, int64), range (m), bearing, elevation (rad) (M, float64),
// sender (M, int64: the sending robot's index, -1 for a board of no robot)
// and data (M x the largest payload, uint8, zero-padded).
py::dict RangeAndBearing(const Scene& scene, const ModelLayout& layout);
// Sets what each robot's first board sends: row i of `data` (N x k, bytes
// 0..255, k at most the payload size) for robot i. Throws ValueError.
void SetRangeAndBearingData(Scene* scene, const ModelLayout& layout, const py::object& data);
// Ground sensor readings, N x ground sensors: each one's value (its grey
// level, 0/1 in binary mode, a colour sensor's grey level).
Array Ground(const Scene& scene, const ModelLayout& layout, const py::object& out);
// Light sensor readings (modules/light), N x light sensors.
Array Light(const Scene& scene, const ModelLayout& layout, const py::object& out);

// Joint positions (what = 0) or velocities (1), N x joints.
Array Joints(const Scene& scene, const ModelLayout& layout, int what, const py::object& out);

}  // namespace swarmsim::python
