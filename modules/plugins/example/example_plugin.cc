// An example plugin (framework/plugin_api.h).
// Script commands:
//   sim.exampleSum(a, b, ...) or sim.exampleSum({a, b, ...}) -> the sum
//   sim.exampleWhereAmI() -> {x, y, z} of the calling script's object, and the robot index
//   sim.robotMoveAndAvoidObstacles(duration [, speed]) -> end time (s)
//       the paper's high-level command (V-REP §3.3): the calling robot drives
//       at `speed` m/s (default: its wheel_speed parameter, else 0.05) for
//       `duration` s, turning away from what its proximity sensors see, then
//       stops. It returns at once; a threaded script waits with
//       sim.wait(duration) or sim.waitUntil(function() return
//       not sim.robotIsMoving() end). The robot needs ./leftMotor and
//       ./rightMotor (velocity joints, axles along +y) and proximity sensors
//       named prox (ring, prox[0] ahead), as worlds/models/footbot.yaml.
//   sim.robotIsMoving() -> 1 while the command above runs, else nil
//   sim.examplePhaseCounts() -> {after_sense, before_control, after_control,
//       after_physics, record}: how often each phase callback has run in this world
// Phase callbacks: a per-robot after_control callback steers every robot
// that runs robotMoveAndAvoidObstacles (robots in parallel); whole-world
// callbacks count the phases.
// Object type `beacon` (ABI 4; {type: beacon, radius: 1, strength: 2} in a
// model): sim.readBeacon(h) -> {radius, strength}; the radius scales with the
// model. Record-phase module `beacon_coverage`: records
// near_beacon_fraction, the fraction of robots carrying no beacon whose root
// lies within the radius of some beacon (in the plane), every step.
// Sensor type `spectrum` (ABI 4, a reading of 256 numbers): the light's
// intensity in 256 bands, band k of 256 getting intensity * (k + 1) / 256.
// Sensor type `light` ({type: plugin_sensor, sensor: light} in a model):
// reading {intensity, distance}, distance (m) from the sensor to the light
// at the parameters (light_x, light_y, light_z) (default 0, 0, 1), and
// intensity = light_power / (1 + distance^2) (light_power default 1).
// Vision filter elements (ABI 5), for a sensor's `filters:` list:
// `invert` (a colour or grey image or a mask -> the same, each byte 255 - v)
// and `brightness` ({type: brightness, gain: 1.5, offset: 0.1}: a colour or
// grey image -> the same, v' = clamp(gain v + 255 offset); its packet is the
// mean of the result, 0..1).
// Native controllers (ABI 6; `native_controller: NAME` on a models entry):
// `relay`: each step the robot sends its `greeting` parameter (a string,
// default "hi") to every other robot (a global message), counts the
// messages it received with that text, and sets its ./wheel joint's target
// velocity to that count plus a draw of its random stream times
// `noise` (default 0). `faulty`: fails in its step when the step count
// reaches the `fail_step` parameter (default 2) on the robots whose index is
// at least `fail_robot` (default 0), and in init if `fail_init` is 1.
// sim.exampleLiveControllers() -> how many controller states are alive
// (init made, cleanup not yet freed).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "framework/plugin_api.h"

namespace {

SwarmsimValue Number(double x) { return {kSwarmsimNumber, x, nullptr, nullptr, 0}; }

int Sum(const SwarmsimCallContext*, const SwarmsimValue* args, int n, SwarmsimValue* results, int,
        char* error, size_t error_size, void*) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    if (args[i].type == kSwarmsimNumber) {
      sum += args[i].number;
    } else if (args[i].type == kSwarmsimNumbers) {
      for (size_t k = 0; k < args[i].size; ++k) sum += args[i].numbers[k];
    } else {
      std::snprintf(error, error_size, "argument %d must be a number or an array of numbers",
                    i + 1);
      return -1;
    }
  }
  results[0] = Number(sum);
  return 1;
}

int WhereAmI(const SwarmsimCallContext* c, const SwarmsimValue*, int, SwarmsimValue* results, int,
             char* error, size_t error_size, void*) {
  thread_local double p[3];  // results stay valid until the command returns
  if (!c->api->object_position(c->world, c->script_object, p)) {
    std::snprintf(error, error_size, "only a child script has an object");
    return -1;
  }
  results[0] = {kSwarmsimNumbers, 0, nullptr, p, 3};
  results[1] = Number(static_cast<double>(c->robot));
  return 2;
}

// --- robotMoveAndAvoidObstacles ------------------------------------------------------

constexpr int kMaxSensors = 64;
constexpr double kHalfAxle = 0.07;  // m, wheel to body centre (foot-bot)

// One robot's running command.
struct Behaviour {
  double start_time = 0, end_time = 0;  // s
  double wheel_speed = 0;               // rad/s
  double wheel_radius = 0.029;          // m
  int64_t left = 0, right = 0;
  std::vector<int64_t> sensors;  // prox[0..], evenly spaced counter-clockwise from ahead
};

std::mutex g_mutex;
std::map<std::pair<const void*, int>, Behaviour> g_behaviours;  // (world, robot)
std::atomic<int> g_running{0};  // entries in g_behaviours, to skip the lock when 0

int MoveAndAvoid(const SwarmsimCallContext* c, const SwarmsimValue* args, int n,
                 SwarmsimValue* results, int, char* error, size_t error_size, void*) {
  if (n < 1 || args[0].type != kSwarmsimNumber || !(args[0].number >= 0)) {
    std::snprintf(error, error_size, "expected (duration [, speed]): seconds >= 0");
    return -1;
  }
  if (c->robot < 0) {
    std::snprintf(error, error_size, "only a robot's script can drive it");
    return -1;
  }
  const SwarmsimWorldApi& api = *c->api;
  Behaviour b;
  if (!api.find_object(c->world, c->script_object, ":/leftMotor", &b.left) ||
      !api.find_object(c->world, c->script_object, ":/rightMotor", &b.right)) {
    std::snprintf(error, error_size, "the robot has no :/leftMotor and :/rightMotor joints");
    return -1;
  }
  for (int k = 0; k < kMaxSensors; ++k) {
    char path[32];
    std::snprintf(path, sizeof path, ":/prox[%d]", k);
    int64_t h = 0;
    if (!api.find_object(c->world, c->script_object, path, &h)) break;
    b.sensors.push_back(h);
  }
  double speed = 0.05;
  api.number_parameter(c->world, c->robot, "wheel_speed", &speed);
  if (n >= 2 && args[1].type == kSwarmsimNumber) speed = args[1].number;
  api.number_parameter(c->world, c->robot, "wheel_radius", &b.wheel_radius);
  b.wheel_speed = speed / b.wheel_radius;
  b.start_time = api.time(c->world);
  b.end_time = b.start_time + args[0].number;
  {
    std::lock_guard lock(g_mutex);
    if (g_behaviours.insert_or_assign({c->world, c->robot}, std::move(b)).second) ++g_running;
  }
  results[0] = Number(api.time(c->world) + args[0].number);
  return 1;
}

int IsMoving(const SwarmsimCallContext* c, const SwarmsimValue*, int, SwarmsimValue* results, int,
             char*, size_t, void*) {
  std::lock_guard lock(g_mutex);
  results[0] = g_behaviours.count({c->world, c->robot}) ? Number(1) : SwarmsimValue{};
  return 1;
}

// Per robot, after its scripts ran: steer while the command runs, then stop.
int Steer(const SwarmsimCallContext* c, char*, size_t, void*) {
  if (g_running.load(std::memory_order_relaxed) == 0) return 0;
  const SwarmsimWorldApi& api = *c->api;
  Behaviour b;
  {
    std::lock_guard lock(g_mutex);
    auto it = g_behaviours.find({c->world, c->robot});
    if (it == g_behaviours.end()) return 0;
    const double now = api.time(c->world);
    if (now >= it->second.end_time || now < it->second.start_time /* an older world's */) {
      api.set_joint_target_velocity(c->world, c->robot, it->second.left, 0);
      api.set_joint_target_velocity(c->world, c->robot, it->second.right, 0);
      g_behaviours.erase(it);
      --g_running;
      return 0;
    }
    b = it->second;
  }
  // Sum of the readings as vectors toward what each sensor sees (nearer
  // counts more), as the diffusion controller: turn away from it.
  double x = 0, y = 0;
  const double count = static_cast<double>(b.sensors.size());
  for (size_t i = 0; i < b.sensors.size(); ++i) {
    double distance = 0;
    if (api.read_proximity_sensor(c->world, b.sensors[i], &distance) == 1) {
      const double a = 2 * M_PI * static_cast<double>(i) / count;
      const double value = 1 / (1 + 10 * distance);
      x += value * std::cos(a), y += value * std::sin(a);
    }
  }
  double left = b.wheel_speed, right = b.wheel_speed;
  if (x * x + y * y > 0) {
    const double angle = std::atan2(y, x);
    const double turn = 2.0;  // rad/s
    if (std::abs(angle) < M_PI / 2) {
      // Something ahead: turn on the spot away from it.
      const double w = (angle > 0 ? -turn : turn) * kHalfAxle / b.wheel_radius;
      left = -w, right = w;
    }
  }
  api.set_joint_target_velocity(c->world, c->robot, b.left, left);
  api.set_joint_target_velocity(c->world, c->robot, b.right, right);
  return 0;
}

// --- Phase counts ----------------------------------------------------------------------

std::mutex g_count_mutex;
std::map<const void*, std::vector<double>> g_counts;  // world -> count per phase

int CountPhase(const SwarmsimCallContext* c, char*, size_t, void* phase) {
  const int p = static_cast<int>(reinterpret_cast<intptr_t>(phase));
  std::lock_guard lock(g_count_mutex);
  std::vector<double>& counts = g_counts[c->world];
  // A new world at the same address starts afresh.
  if (p == kSwarmsimAfterSense && c->api->step_count(c->world) == 0) counts.clear();
  counts.resize(kSwarmsimPhaseCount);
  counts[p] += 1;
  return 0;
}

int PhaseCounts(const SwarmsimCallContext* c, const SwarmsimValue*, int, SwarmsimValue* results,
                int, char*, size_t, void*) {
  thread_local std::vector<double> out;
  {
    std::lock_guard lock(g_count_mutex);
    out = g_counts[c->world];
  }
  out.resize(kSwarmsimPhaseCount);
  results[0] = {kSwarmsimNumbers, 0, nullptr, out.data(), out.size()};
  return 1;
}

// --- Light sensor ----------------------------------------------------------------------

int SenseLight(const SwarmsimCallContext* c, int64_t sensor, double* values, int max_values,
               char* error, size_t error_size, void*) {
  const SwarmsimWorldApi& api = *c->api;
  double p[3];
  if (max_values < 2 || !api.object_position(c->world, sensor, p)) {
    std::snprintf(error, error_size, "the sensor object is gone");
    return -1;
  }
  double light[3] = {0, 0, 1}, power = 1;
  api.number_parameter(c->world, c->robot, "light_x", &light[0]);
  api.number_parameter(c->world, c->robot, "light_y", &light[1]);
  api.number_parameter(c->world, c->robot, "light_z", &light[2]);
  api.number_parameter(c->world, c->robot, "light_power", &power);
  const double d =
      std::sqrt((p[0] - light[0]) * (p[0] - light[0]) + (p[1] - light[1]) * (p[1] - light[1]) +
                (p[2] - light[2]) * (p[2] - light[2]));
  values[0] = power / (1 + d * d);
  values[1] = d;
  return 2;
}

int SenseSpectrum(const SwarmsimCallContext* c, int64_t sensor, double* values, int max_values,
                  char* error, size_t error_size, void* user_data) {
  double light[2];
  if (SenseLight(c, sensor, light, 2, error, error_size, user_data) < 0) return -1;
  for (int k = 0; k < max_values; ++k) values[k] = light[0] * (k + 1) / max_values;
  return max_values;
}

// --- Beacons ----------------------------------------------------------------------------

const SwarmsimObjectKey kBeaconKeys[] = {
    {"radius", 0.5, 0, 1000, 1, "m, how far the beacon reaches (scales with the model)"},
    {"strength", 1, 0, 1e6, 0, "its signal strength"},
};

int ReadBeacon(const SwarmsimCallContext* c, const SwarmsimValue* args, int n,
               SwarmsimValue* results, int, char* error, size_t error_size, void*) {
  thread_local double values[2];
  if (n < 1 || args[0].type != kSwarmsimNumber ||
      c->api->object_values(c->world, static_cast<int64_t>(args[0].number), values, 2) != 2) {
    std::snprintf(error, error_size, "argument 1 must be the handle of a beacon");
    return -1;
  }
  results[0] = {kSwarmsimNumbers, 0, nullptr, values, 2};
  return 1;
}

int BeaconCoverage(const SwarmsimCallContext* c, char* error, size_t error_size, void*) {
  const SwarmsimWorldApi& api = *c->api;
  struct Beacon {
    double x, y, radius;
    int robot;
  };
  thread_local std::vector<int64_t> handles;
  thread_local std::vector<Beacon> beacons;
  const int count = api.objects_of_type(c->world, "beacon", nullptr, 0);
  if (count < 0) {
    std::snprintf(error, error_size, "no beacon object type");
    return -1;
  }
  handles.resize(static_cast<size_t>(count));
  api.objects_of_type(c->world, "beacon", handles.data(), count);
  beacons.clear();
  std::vector<char> carries(static_cast<size_t>(api.robot_count(c->world)), 0);
  for (int64_t h : handles) {
    double p[3], v[2];
    if (!api.object_position(c->world, h, p) || api.object_values(c->world, h, v, 2) != 2) continue;
    const int robot = api.robot_of(c->world, h);
    if (robot >= 0 && robot < static_cast<int>(carries.size())) carries[robot] = 1;
    beacons.push_back({p[0], p[1], v[0], robot});
  }
  int robots = 0, near = 0;
  for (int r = 0; r < static_cast<int>(carries.size()); ++r) {
    double p[3];
    const int64_t root = api.robot_root(c->world, r);
    if (carries[r] || root == 0 || !api.object_position(c->world, root, p)) continue;
    ++robots;
    for (const Beacon& b : beacons) {
      if (std::hypot(p[0] - b.x, p[1] - b.y) <= b.radius) {
        ++near;
        break;
      }
    }
  }
  api.record_metric(c->world, -1, "near_beacon_fraction",
                    robots > 0 ? static_cast<double>(near) / robots : 0);
  return 0;
}

// --- Vision filters ----------------------------------------------------------------------

size_t Bytes(const SwarmsimImage* image) {
  return static_cast<size_t>(image->width) * static_cast<size_t>(image->height) *
         (image->kind == kSwarmsimColourImage ? 3 : 1);
}

int Invert(const SwarmsimImage* in, SwarmsimImage* out, const double*, double*, int, char*, size_t,
           void*) {
  for (size_t i = 0, n = Bytes(in); i < n; ++i) out->pixels[i] = 255 - in->pixels[i];
  return 0;
}

const SwarmsimObjectKey kBrightnessKeys[] = {
    {"gain", 1, 0, 16, 0, "factor on each channel"},
    {"offset", 0, -1, 1, 0, "added to each channel after the gain, -1..1 (1 = 255)"},
};

int Brightness(const SwarmsimImage* in, SwarmsimImage* out, const double* parameters,
               double* values, int max_values, char* error, size_t error_size, void*) {
  if (max_values < 1) {
    std::snprintf(error, error_size, "no room for the mean");
    return -1;
  }
  const double gain = parameters[0], offset = 255 * parameters[1];
  double sum = 0;
  const size_t n = Bytes(in);
  for (size_t i = 0; i < n; ++i) {
    const double v = std::fmin(255, std::fmax(0, gain * in->pixels[i] + offset));
    out->pixels[i] = static_cast<uint8_t>(v + 0.5);
    sum += out->pixels[i];
  }
  values[0] = n > 0 ? sum / (255.0 * static_cast<double>(n)) : 0;
  return 1;
}

// --- Native controllers ---------------------------------------------------------------

std::atomic<int> g_live_controllers{0};

struct RelayState {
  int64_t wheel = 0;
  std::string greeting;
  double noise = 0;
};

int RelayInit(const SwarmsimCallContext* c, void** state, char* error, size_t error_size, void*) {
  RelayState* s = new (std::nothrow) RelayState;
  if (s == nullptr) return -1;
  *state = s;
  ++g_live_controllers;
  const SwarmsimWorldApi& api = *c->api;
  if (!api.find_object(c->world, c->script_object, "./wheel", &s->wheel)) {
    std::snprintf(error, error_size, "no ./wheel joint");
    return -1;
  }
  SwarmsimValue greeting;
  s->greeting = "hi";
  if (api.parameter(c->world, c->robot, "greeting", &greeting) && greeting.type == kSwarmsimString)
    s->greeting.assign(greeting.text, greeting.size);
  api.number_parameter(c->world, c->robot, "noise", &s->noise);
  return 0;
}

int RelayStep(const SwarmsimCallContext* c, void* state, char*, size_t, void*) {
  const RelayState& s = *static_cast<const RelayState*>(state);
  const SwarmsimWorldApi& api = *c->api;
  int count = 0;
  SwarmsimMessage m;
  while (api.receive_message(c->world, c->robot, &m) == 1)
    if (std::string(m.data, m.size) == s.greeting) ++count;
  api.send_message(c->world, c->robot, kSwarmsimMessageGlobal, s.greeting.data(), s.greeting.size(),
                   0, 0, 0);
  const double noise = s.noise != 0 ? s.noise * api.random_uniform(c->world, c->robot) : 0;
  api.set_joint_target_velocity(c->world, c->robot, s.wheel, count + noise);
  return 0;
}

void FreeState(const SwarmsimCallContext*, void* state, void*) {
  if (state == nullptr) return;
  --g_live_controllers;
  ::operator delete(state);  // FaultyInit's byte
}

void RelayCleanup(const SwarmsimCallContext*, void* state, void*) {
  if (state == nullptr) return;
  --g_live_controllers;
  delete static_cast<RelayState*>(state);
}

int FaultyInit(const SwarmsimCallContext* c, void** state, char* error, size_t error_size, void*) {
  *state = ::operator new(1, std::nothrow);
  if (*state != nullptr) ++g_live_controllers;
  double fail_init = 0;
  c->api->number_parameter(c->world, c->robot, "fail_init", &fail_init);
  if (fail_init == 1) {
    std::snprintf(error, error_size, "cannot start robot %d", c->robot);
    return -1;
  }
  return 0;
}

int FaultyStep(const SwarmsimCallContext* c, void*, char* error, size_t error_size, void*) {
  double fail_step = 2, fail_robot = 0;
  c->api->number_parameter(c->world, c->robot, "fail_step", &fail_step);
  c->api->number_parameter(c->world, c->robot, "fail_robot", &fail_robot);
  const int64_t step = c->api->step_count(c->world);
  if (static_cast<double>(step) >= fail_step && c->robot >= fail_robot) {
    std::snprintf(error, error_size, "broke at step %lld", static_cast<long long>(step));
    return -1;
  }
  return 0;
}

int LiveControllers(const SwarmsimCallContext*, const SwarmsimValue*, int, SwarmsimValue* results,
                    int, char*, size_t, void*) {
  results[0] = Number(g_live_controllers.load());
  return 1;
}

}  // namespace

extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }

extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) {
  r->set_info(r->impl, "example", "6.0",
              "example plugin: exampleSum, exampleWhereAmI, robotMoveAndAvoidObstacles, light, "
              "beacon, invert, brightness, relay, faulty");
  struct Command {
    const char* name;
    const char* description;
    SwarmsimCommand function;
  };
  const Command commands[] = {
      {"exampleSum", "sum of numbers and number arrays", Sum},
      {"exampleWhereAmI", "position of the calling script's object", WhereAmI},
      {"robotMoveAndAvoidObstacles", "drive for a duration, avoiding obstacles", MoveAndAvoid},
      {"robotIsMoving", "true while robotMoveAndAvoidObstacles runs", IsMoving},
      {"examplePhaseCounts", "how often each phase callback ran", PhaseCounts},
      {"readBeacon", "{radius, strength} of a beacon object", ReadBeacon},
      {"exampleLiveControllers", "controller states alive", LiveControllers},
  };
  for (const Command& c : commands)
    if (r->add_command(r->impl, c.name, c.description, c.function, nullptr) != 0) return -1;
  if (r->add_phase_callback(r->impl, kSwarmsimAfterControl, 1, Steer, nullptr) != 0) return -1;
  for (intptr_t phase = 0; phase < kSwarmsimPhaseCount; ++phase)
    if (r->add_phase_callback(r->impl, static_cast<int>(phase), 0, CountPhase,
                              reinterpret_cast<void*>(phase)) != 0)
      return -1;
  if (r->add_sensor_type(r->impl, "light", "{intensity, distance} from the light_x/y/z parameters",
                         SenseLight, nullptr) != 0)
    return -1;
  if (r->add_sensor_type_of_size(r->impl, "spectrum", "the light's intensity in 256 bands", 256,
                                 SenseSpectrum, nullptr) != 0)
    return -1;
  if (r->add_object_type(r->impl, "beacon", "a marker robots are near or not (radius, strength)",
                         kBeaconKeys, 2) != 0)
    return -1;
  if (r->add_phase_callback(r->impl, kSwarmsimRecord, 0, BeaconCoverage, nullptr) != 0) return -1;
  const int images = kSwarmsimColourImage | kSwarmsimGreyImage;
  if (r->add_vision_filter(r->impl, "invert", "each byte 255 - v", images | kSwarmsimMask, 0,
                           nullptr, 0, 0, Invert, nullptr) != 0)
    return -1;
  if (r->add_vision_filter(r->impl, "brightness", "gain and offset on each channel", images, 0,
                           kBrightnessKeys, 2, 1, Brightness, nullptr) != 0)
    return -1;
  if (r->add_controller(r->impl, "relay", "greets the other robots, counts their greetings",
                        RelayInit, RelayStep, RelayCleanup, nullptr) != 0 ||
      r->add_controller(r->impl, "faulty", "fails at a given step (tests)", FaultyInit, FaultyStep,
                        FreeState, nullptr) != 0)
    return -1;
  return 0;
}
