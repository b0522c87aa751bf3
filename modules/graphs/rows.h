// The row of a graph object (objects.cc) and its data streams (streams.cc):
// V-REP's graphs (paper §2.1). Internal to modules/graphs.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace swarmsim::graphs {

// What a stream reads.
enum class StreamKind : uint8_t {
  kPosition,         // m, world frame
  kOrientation,      // rad: roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll))
  kVelocity,         // m/s, world frame
  kAngularVelocity,  // rad/s, world frame
  kJoint,            // a joint's position, rad or m
  kJointVelocity,    // rad/s or m/s
  kProximity,        // a proximity sensor's distance, m (nan: nothing detected)
  kForce,            // a force sensor's force, N, sensor frame (nan: no reading)
  kTorque,           // and torque, N m
  kDistance,         // a distance object's distance, m (nan: nothing within its threshold)
  kScript,           // what a script set with sim.setGraphStreamValue this sample (else nan)
};

// Which number of a vector a stream takes (kNone: the reading is a number).
enum class Component : uint8_t { kNone, kX, kY, kZ, kNorm, kRoll, kPitch, kYaw };

struct StreamSpec {
  std::string name;  // the CSV column and the plot's label
  StreamKind kind = StreamKind::kPosition;
  Component component = Component::kNone;
  std::string path;  // the object, resolved from the graph (empty for kScript)
  std::string unit;  // for axis labels: "m", "rad", "rad or m" (a joint's until resolved)
};

enum class GraphKind : uint8_t { kTime, kXy, kXyz };

struct GraphRow {
  // Settings.
  GraphKind kind = GraphKind::kTime;
  int every = 1;            // steps between samples
  int64_t buffer = 100000;  // samples kept
  bool cyclic = false;      // when full: keep the last `buffer` samples (else the first)
  bool png = true;          // draw the graph (CSV always)
  std::string title;        // empty: the graph's path
  std::vector<StreamSpec> streams;
  std::string where;  // "file:line:column" of `streams`, for errors found later
  // State: the values scripts set since the last sample (kScript streams;
  // nan for the others and for what no script set).
  std::vector<double> script_values;
};

// Parses one entry of `streams` ("[NAME =] KIND [PATH] [COMPONENT]") and
// appends its streams (a vector without a component gives three). Throws
// swarmsim::Error with a message about `text` (the caller adds where).
void ParseStream(std::string_view text, std::vector<StreamSpec>* out);

}  // namespace swarmsim::graphs
