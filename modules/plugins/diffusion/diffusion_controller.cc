// Foot-bot diffusion as a native controller (framework/plugin_api.h, ABI 6):
// scripts/diffusion.lua in C, with the same arithmetic in the same order, so
// that a world running it (worlds/diffusion_native.yaml) moves its robots
// exactly as the Lua world does. Drive straight, and turn away from whatever
// the proximity ring (./prox[0] ahead, then counter-clockwise) sees.
//
// Parameters (sim.getParam's): wheel_speed (m/s, default 0.05), wheel_radius
// (m, 0.029), go_straight_angle_deg (7.5), delta (0.1); slow_distance (m,
// default 0: off): half speed while the look-ahead sensor ./front sees
// something that close. The robot needs ./leftMotor, ./rightMotor and a ring
// of proximity sensors named prox.
//
// Registers the controller `diffusion`:
//   models: [{model: models/footbot.yaml, ..., native_controller: diffusion}]
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <vector>

#include "framework/plugin_api.h"

namespace {

constexpr double kRange = 0.1;   // m, the proximity sensors' range (as diffusion.lua)
constexpr int kMaxSensors = 64;  // the ring's sensors looked for

// The direction of each sensor of a ring of n: the same for every robot
// whose ring has n sensors, so made once per n and shared.
struct Ring {
  std::vector<double> cos_a, sin_a;
};

const Ring& RingOf(size_t n) {
  static std::mutex mutex;
  static std::map<size_t, std::unique_ptr<const Ring>> rings;
  const std::lock_guard<std::mutex> lock(mutex);
  std::unique_ptr<const Ring>& ring = rings[n];
  if (!ring) {
    auto made = std::make_unique<Ring>();
    made->cos_a.resize(n);
    made->sin_a.resize(n);
    for (size_t i = 0; i < n; ++i) {
      // As Lua evaluates 2 * math.pi * i / 24: left to right, in doubles.
      const double a = 2 * M_PI * static_cast<double>(i) / static_cast<double>(n);
      made->cos_a[i] = std::cos(a);
      made->sin_a[i] = std::sin(a);
    }
    ring = std::move(made);
  }
  return *ring;
}

// One robot's state: what diffusion.lua's sysCall_init computes.
struct Robot {
  int64_t left_motor = 0, right_motor = 0;
  int64_t front = 0;             // the look-ahead sensor, if slow_distance > 0
  std::vector<int64_t> sensors;  // the ring, as many as it has
  const Ring* ring = nullptr;    // direction of each sensor
  double wheel_speed = 0;        // rad/s
  double straight_angle = 0;     // rad
  double delta = 0;
  double slow_distance = 0;  // m
};

double Param(const SwarmsimCallContext* c, const char* name, double fallback) {
  double value = fallback;
  c->api->number_parameter(c->world, c->robot, name, &value);
  return value;
}

int Init(const SwarmsimCallContext* c, void** state, char* error, size_t error_size, void*) {
  Robot* robot = new (std::nothrow) Robot;
  if (robot == nullptr) {
    std::snprintf(error, error_size, "out of memory");
    return -1;
  }
  *state = robot;  // cleanup frees it, even after a failure here
  const SwarmsimWorldApi& api = *c->api;
  robot->wheel_speed = Param(c, "wheel_speed", 0.05) / Param(c, "wheel_radius", 0.029);
  // math.rad(x) is x * (pi / 180).
  robot->straight_angle = Param(c, "go_straight_angle_deg", 7.5) * (M_PI / 180.0);
  robot->delta = Param(c, "delta", 0.1);
  robot->slow_distance = Param(c, "slow_distance", 0);
  if (!api.find_object(c->world, c->script_object, "./leftMotor", &robot->left_motor) ||
      !api.find_object(c->world, c->script_object, "./rightMotor", &robot->right_motor)) {
    std::snprintf(error, error_size, "the robot has no ./leftMotor and ./rightMotor joints");
    return -1;
  }
  if (robot->slow_distance > 0 &&
      !api.find_object(c->world, c->script_object, "./front", &robot->front)) {
    std::snprintf(error, error_size, "slow_distance > 0 needs a look-ahead sensor ./front");
    return -1;
  }
  try {
    int64_t found[kMaxSensors];
    int n = 0;
    // "./prox[n]", written by hand: snprintf was ~8% of the CPU of starting
    // a large swarm's controllers (24 paths a robot).
    char path[32] = "./prox[";
    constexpr size_t kHead = sizeof "./prox[" - 1;
    for (; n < kMaxSensors; ++n) {
      char* end = std::to_chars(path + kHead, path + sizeof path - 2, n).ptr;
      end[0] = ']';
      end[1] = '\0';
      if (!api.find_object(c->world, c->script_object, path, &found[n])) break;
    }
    robot->sensors.assign(found, found + n);  // one block of exactly n
    robot->ring = &RingOf(robot->sensors.size());
  } catch (const std::bad_alloc&) {
    std::snprintf(error, error_size, "out of memory");
    return -1;
  }
  if (robot->sensors.empty()) {
    std::snprintf(error, error_size, "the robot has no proximity ring ./prox[0], ./prox[1], ...");
    return -1;
  }
  return 0;
}

int Step(const SwarmsimCallContext* c, void* state, char* error, size_t error_size, void*) {
  const Robot& robot = *static_cast<const Robot*>(state);
  const SwarmsimWorldApi& api = *c->api;
  // Sum of the readings as vectors pointing at what each sensor sees.
  double distances[kMaxSensors];
  if (api.read_proximity_sensors(c->world, robot.sensors.data(),
                                 static_cast<int>(robot.sensors.size()), distances) < 0) {
    std::snprintf(error, error_size, "a sensor of the ring is gone");
    return -1;
  }
  double x = 0, y = 0;
  for (size_t i = 0; i < robot.sensors.size(); ++i) {
    if (distances[i] < 0) continue;
    const double value = 1 - distances[i] / kRange;
    x = x + value * robot.ring->cos_a[i];
    y = y + value * robot.ring->sin_a[i];
  }
  const double angle = std::atan2(y, x);
  double left, right;
  if (std::fabs(angle) <= robot.straight_angle && std::sqrt(x * x + y * y) < robot.delta) {
    left = robot.wheel_speed, right = robot.wheel_speed;  // nothing ahead: straight on
  } else if (angle > 0) {
    left = robot.wheel_speed, right = 0;  // obstacle on the left: turn right
  } else {
    left = 0, right = robot.wheel_speed;  // obstacle on the right: turn left
  }
  if (robot.front != 0) {
    double ahead = 0;
    if (api.read_proximity_sensor(c->world, robot.front, &ahead) == 1 &&
        ahead < robot.slow_distance)
      left = left / 2, right = right / 2;
  }
  api.set_joint_target_velocity(c->world, c->robot, robot.left_motor, left);
  api.set_joint_target_velocity(c->world, c->robot, robot.right_motor, right);
  return 0;
}

void Cleanup(const SwarmsimCallContext*, void* state, void*) { delete static_cast<Robot*>(state); }

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "diffusion_controller", "1.0",
              "foot-bot diffusion (scripts/diffusion.lua) as a native controller");
  return r->add_controller(r->impl, "diffusion",
                           "drive straight, turn away from what the proximity ring sees", Init,
                           Step, Cleanup, nullptr);
}
