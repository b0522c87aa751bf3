// The swarmsim plugin interface: the one header a plugin includes.
//
// A plugin is a shared library loaded from a world (`plugins: [path]`) or
// with `swarmsim run --plugin PATH`. It exports two C functions:
//
//   extern "C" int swarmsim_plugin_abi_version(void) { return SWARMSIM_PLUGIN_ABI_VERSION; }
//   extern "C" int swarmsim_plugin_register(const SwarmsimRegistrar* r) { ...; return 0; }
//
// and registers script commands through the registrar: a command `name`
// is called from Lua as sim.name(...); and per-phase callbacks, which the
// world runs at fixed points of each step (SwarmsimPhase); and sensor types
// (ABI 3), read by scripts with sim.readPluginSensor; and object types (ABI
// 4) that model files place like built-in ones; and vision-sensor filter
// elements (ABI 5) that a sensor's `filters:` list names; and native
// controllers (ABI 6) that a models entry attaches with `native_controller:`,
// called once per robot per step in the control phase; their world API
// reads and sets range-and-bearing boards (ABI 7), and reads light and
// ground sensors, sets LEDs and sends and hears IR messages (ABI 8: what a
// Kilobot's firmware needs). Arguments and
// results are numbers, strings and number arrays (SwarmsimValue); no Lua
// type crosses this interface. Everything here is plain C, so a plugin
// built with another compiler works as long as the ABI version matches; the
// version changes whenever a struct below does (a plugin of a version from
// SWARMSIM_PLUGIN_ABI_OLDEST up loads: later versions only add at the end).
#ifndef SWARMSIM_PLUGIN_API_H_
#define SWARMSIM_PLUGIN_API_H_

#include <stddef.h>
#include <stdint.h>

#define SWARMSIM_PLUGIN_ABI_VERSION 8
// The oldest ABI this swarmsim still loads: ABI 7 and 8 only added functions
// at the end of SwarmsimWorldApi, so a plugin built for ABI 6 runs unchanged.
#define SWARMSIM_PLUGIN_ABI_OLDEST 6

#ifdef __cplusplus
extern "C" {
#endif

enum SwarmsimValueType {
  kSwarmsimNil = 0,
  kSwarmsimNumber = 1,
  kSwarmsimString = 2,
  kSwarmsimNumbers = 3
};

// One argument or result. Strings and arrays are not owned: arguments live
// for the call; results must stay valid until the command returns to
// swarmsim (e.g. static or per-thread storage of the plugin).
typedef struct SwarmsimValue {
  int type;               // SwarmsimValueType
  double number;          // kSwarmsimNumber
  const char* text;       // kSwarmsimString (UTF-8, not necessarily 0-terminated)
  const double* numbers;  // kSwarmsimNumbers
  size_t size;            // bytes of text, or count of numbers
} SwarmsimValue;

// Scopes of a message (ABI 6), as sim.sendGlobalMessage, sendLocalMessage,
// sendDirectMessage and sendRangeMessage.
enum SwarmsimMessageScope {
  kSwarmsimMessageGlobal = 0,  // every script and controller of the world but the sender
  kSwarmsimMessageLocal = 1,   // the others of the sender's model
  kSwarmsimMessageDirect = 2,  // the script or controller on object `target`
  kSwarmsimMessageRange = 3    // robots whose model root is within `range` m of the sender
};

// A message delivered to a native controller (ABI 6).
typedef struct SwarmsimMessage {
  const char* data;  // bytes, valid until the controller's step returns
  size_t size;
  int64_t sender;    // the sending script's object (a controller's: its root; -1: the main script)
  int has_geometry;  // 0 for a message from the main script: no distance or bearing
  double distance;   // m, from the receiver's model root to the sender
  double bearing;    // rad, of the sender in the receiver's root frame (0 = +x, CCW)
} SwarmsimMessage;

// One reading of a range-and-bearing board (ABI 7), as
// sim.readRangeAndBearing gives it.
typedef struct SwarmsimRangeAndBearingReading {
  // The sender's payload (payload_size bytes), valid until the next sense phase.
  const uint8_t* data;
  size_t size;
  double range;      // m, between the two boards' origins (noise added)
  double bearing;    // rad, in (-pi, pi]: in the receiving board's xy plane from its +x, CCW
  double elevation;  // rad, in [-pi/2, pi/2]: above that plane
} SwarmsimRangeAndBearingReading;

// A message an IR transceiver heard (ABI 8), as sim.readIrMessages gives it.
typedef struct SwarmsimIrMessage {
  // The sender's bytes (as it queued them), valid until the next sense phase.
  const uint8_t* data;
  size_t size;
  double distance;  // m, the receiver's estimate of the distance between the two transceivers
} SwarmsimIrMessage;

// A narrow, read-mostly view of the world the command runs in.
typedef struct SwarmsimWorldApi {
  double (*time)(void* world);  // s, simulation time
  // Position [x, y, z] (m, world frame) of an object; returns 0 if the handle is stale.
  int (*object_position)(void* world, int64_t object, double out[3]);
  // A number parameter as sim.getParam sees it for `robot`; returns 0 if none.
  int (*number_parameter)(void* world, int robot, const char* name, double* out);
  // --- ABI 2 ---
  // Object `path` (sim.getObject syntax: "./a", ":/a", "/a/b", "name[k]") relative
  // to object `from` (0: absolute paths only) into *out; returns 0 if none.
  int (*find_object)(void* world, int64_t from, const char* path, int64_t* out);
  // Model root of robot `robot`; 0 if there is no such live robot.
  int64_t (*robot_root)(void* world, int robot);
  // Last reading of a proximity sensor: 1 and the distance (m) if it detects
  // something, 0 if not, -1 if `sensor` is not a proximity sensor.
  int (*read_proximity_sensor)(void* world, int64_t sensor, double* distance);
  // Sets a velocity-mode joint's target velocity (rad/s or m/s). `robot` must
  // be the caller's (a command passes context->robot; a phase callback may act
  // for any robot) and own the joint; returns 0 otherwise.
  int (*set_joint_target_velocity)(void* world, int robot, int64_t joint, double velocity);
  // Step count and number of robots (robot indices are 0..count-1).
  int64_t (*step_count)(void* world);
  int (*robot_count)(void* world);
  // --- ABI 4 ---
  // The values of an object of a plugin's object type (its keys, in the
  // order the type declared them) into out[0..max); returns how many it has,
  // or -1 if `object` is not of a plugin's type (or is stale).
  int (*object_values)(void* world, int64_t object, double* out, int max);
  // The objects of the type `type` (a plugin's or a built-in one, e.g.
  // "beacon", "proximity_sensor"), in handle order, into out[0..max);
  // returns how many there are (possibly more than max), or -1 for an
  // unknown type.
  int (*objects_of_type)(void* world, const char* type, int64_t* out, int max);
  // The robot (model instance) `object` belongs to; -1 for an object
  // outside every robot or a stale handle.
  int (*robot_of)(void* world, int64_t object);
  // A row of metrics.csv for this step: robot -1 for a swarm-level value.
  // From record-phase callbacks only (kSwarmsimRecord); returns 0, or -1
  // elsewhere or for a bad robot or name (empty, or a swarm metric the
  // world's metrics: list records).
  int (*record_metric)(void* world, int robot, const char* name, double value);
  // --- ABI 6 ---
  // The last readings of `count` proximity sensors in one call:
  // distances[i] is the distance (m) to what sensors[i] detects, or -1 when
  // it detects nothing (or is not a proximity sensor). Returns how many
  // detect something, or -1 if some handle is not a live proximity sensor.
  int (*read_proximity_sensors)(void* world, const int64_t* sensors, int count, double* distances);
  // The last reading of a plugin sensor (ABI 3) into out[0..max); returns how
  // many numbers it holds (possibly more than max), 0 before its first sense,
  // -1 if `sensor` is not a plugin sensor.
  int (*read_plugin_sensor)(void* world, int64_t sensor, double* out, int max);
  // Sets a position-mode joint's target position (rad or m), with the rules
  // of set_joint_target_velocity; returns 0 otherwise.
  int (*set_joint_target_position)(void* world, int robot, int64_t joint, double position);
  // A joint's position (rad or m) and velocity; returns 0 if `joint` is not a live joint.
  int (*joint_state)(void* world, int64_t joint, double* position, double* velocity);
  // A parameter as sim.getParam sees it for `robot` (its model's, else the
  // world's): a number (a boolean as 1 or 0) or a string (text valid while
  // the world lives); returns 0 if there is none.
  int (*parameter)(void* world, int robot, const char* name, SwarmsimValue* out);
  // Sends a message from `robot` (its model root is the sender, as a script
  // on the root), delivered at the start of the next step as the sim.send*
  // functions' (scope: SwarmsimMessageScope; target: the receiving object of
  // a direct message; range: m, of a range message, line_of_sight: 1 for
  // receivers no static shape hides). Only from that robot's own controller
  // (or per-robot callback). Returns 0, or -1 for a bad scope, target or
  // range, a message over 1 MiB, or a message that does not fit the robot's
  // memory account (simulation.script_memory_mb, run_script_memory_mb).
  int (*send_message)(void* world, int robot, int scope, const char* data, size_t size,
                      int64_t target, double range, int line_of_sight);
  // The next message delivered this step to `robot`'s native controller
  // (sender-handle order, the robot's own skipped; sim.receiveMessage's
  // rules) into *out: returns 1, or 0 when there are no more. Only from that
  // robot's controller.
  int (*receive_message)(void* world, int robot, SwarmsimMessage* out);
  // A uniform number in [0, 1) from `robot`'s own random stream (keyed by
  // seed and robot index, sim.random's). Only from that robot's controller.
  double (*random_uniform)(void* world, int robot);
  // --- ABI 7 ---
  // Sets the bytes a range-and-bearing board sends every step from the next
  // sense phase on (sim.setRangeAndBearingData's rules: kept until set
  // again, padded with zeros to its payload_size). `robot` must be the
  // caller's and own the board. Returns 0, or -1 if `board` is not a live
  // board of `robot`, or `size` is more than its payload_size.
  int (*set_range_and_bearing_data)(void* world, int robot, int64_t board, const uint8_t* data,
                                    size_t size);
  // The readings of a board's last sense phase, nearest first
  // (sim.readRangeAndBearing's), into out[0..max); returns how many there
  // are (possibly more than max), or -1 if `board` is not a live board.
  int (*read_range_and_bearing)(void* world, int64_t board, SwarmsimRangeAndBearingReading* out,
                                int max);
  // --- ABI 8 ---
  // The last reading of a sensor whose reading is one number: a light_sensor
  // (sim.readLightSensor's value) or a ground_sensor (sim.readGroundSensor's
  // value), into *value. Returns 0, or -1 if `sensor` is neither (or stale).
  int (*read_sensor_value)(void* world, int64_t sensor, double* value);
  // Sets an LED's colour (RGB, each clamped to 0..1) and switches it on (on
  // != 0) or off, as sim.setLedColor / sim.setLedOn. `robot` must be the
  // caller's and own the LED. Returns 0, or -1 if `led` is not a live LED of
  // `robot`.
  int (*set_led)(void* world, int robot, int64_t led, double red, double green, double blue,
                 int on);
  // Queues `data` on IR transceiver `ir` of `robot`, to go out once in the
  // next sense phase (replacing a message queued earlier and not yet sent).
  // There it is sent unless the transceiver hears another transmission
  // already on the air (carrier sense): then nothing goes out and the caller
  // queues it again later. Returns 0, or -1 if `ir` is not a live transceiver
  // of `robot` or `size` is more than its payload_size.
  int (*ir_send)(void* world, int robot, int64_t ir, const uint8_t* data, size_t size);
  // Whether a message of transceiver `ir` went out in the last sense phase:
  // 1 if it did, 0 if not (none was queued, or the channel was busy), -1 if
  // `ir` is not a live transceiver.
  int (*ir_sent)(void* world, int64_t ir);
  // The messages transceiver `ir` heard in the last sense phase, in the
  // order they arrived (collided ones are lost), into out[0..max); returns
  // how many there are (possibly more than max), or -1 if `ir` is not a live
  // transceiver.
  int (*ir_receive)(void* world, int64_t ir, SwarmsimIrMessage* out, int max);
} SwarmsimWorldApi;

// Who is calling: the robot and the script's object.
typedef struct SwarmsimCallContext {
  int robot;  // model instance index; -1 for scene and main scripts
  int64_t
      script_object;  // the calling script's object handle (as Lua sees it); 0 for the main script
  void* world;        // pass to the functions of `api`
  const SwarmsimWorldApi* api;
} SwarmsimCallContext;

// A script command. Fills results[0..max_results) and returns how many,
// or -1 after writing a message into `error` (at most error_size bytes, 0-terminated):
// the script then fails at the calling line with that message.
// Commands of different robots run concurrently: keep them thread-safe.
typedef int (*SwarmsimCommand)(const SwarmsimCallContext* context, const SwarmsimValue* args,
                               int arg_count, SwarmsimValue* results, int max_results, char* error,
                               size_t error_size, void* user_data);

// Points of a step where a plugin's phase callbacks run (ABI 2). With a
// world's own main script, "control" means each sim.handleChildScripts call
// and "physics" sim.handleDynamics.
enum SwarmsimPhase {
  kSwarmsimAfterSense = 0,     // sensors have read the state
  kSwarmsimBeforeControl = 1,  // before the child scripts run
  kSwarmsimAfterControl = 2,   // after them, before deferred writes and joint motion
  kSwarmsimAfterPhysics = 3,   // after the dynamics step (poses are current)
  kSwarmsimRecord = 4,         // ABI 4: the record phase, after the swarm metrics
  kSwarmsimPhaseCount = 5
};

// A phase callback. Whole-world callbacks run once per phase on the calling
// thread with context->robot == -1; per-robot ones run once for every live
// robot, robots concurrently (context->robot is the robot; touch only its
// objects). Return 0, or -1 after writing a message into `error`: the run
// stops with it.
typedef int (*SwarmsimPhaseCallback)(const SwarmsimCallContext* context, char* error,
                                     size_t error_size, void* user_data);

// Most numbers one plugin sensor reading holds (ABI 3).
#define SWARMSIM_SENSOR_MAX_VALUES 16

// The sense function of a plugin sensor type (ABI 3). Models declare such
// sensors as objects {type: plugin_sensor, sensor: NAME, name: ...}; in the
// sense phase, before the after_sense callbacks, it runs once for every
// such object of every live robot, robots concurrently (context->robot is
// the robot, -1 for an object outside every robot; context->script_object
// is 0). It writes its reading into values[0..max_values) and returns how
// many it wrote, or -1 after writing a message into `error`: the run stops
// with it. Scripts get the reading with sim.readPluginSensor(sensor).
typedef int (*SwarmsimSensorFunction)(const SwarmsimCallContext* context, int64_t sensor,
                                      double* values, int max_values, char* error,
                                      size_t error_size, void* user_data);

// One world-file key of a plugin's object type (ABI 4): a number, with its
// default and accepted range. Under a size factor s (a model's `scale:`,
// sim.setObjectSizeFactor) the value becomes value * s^length_power: 1 for
// a length, 3 for a mass or force, 0 for what does not scale.
typedef struct SwarmsimObjectKey {
  const char* name;
  double default_value;
  double min, max;
  int length_power;
  const char* doc;  // one line: unit and meaning
} SwarmsimObjectKey;

// What a vision-sensor filter element takes and gives (ABI 5): bits, so an
// element may take several kinds.
enum SwarmsimImageKind {
  kSwarmsimColourImage = 1,  // RGB, 3 bytes a pixel
  kSwarmsimGreyImage = 2,    // 1 byte a pixel
  kSwarmsimMask = 4,         // 1 byte a pixel, 0 or 255
  kSwarmsimDepthImage = 8,   // 1 float a pixel, metres along the view axis
  kSwarmsimValues = 16       // numbers only: the image goes no further
};

// A work image passed to a filter element (ABI 5); rows top to bottom.
typedef struct SwarmsimImage {
  int width, height;  // pixels
  int kind;           // one SwarmsimImageKind
  uint8_t* pixels;    // colour, grey or mask; else null
  float* depth;       // depth image; else null
} SwarmsimImage;

// A plugin's filter element (ABI 5). Reads `input` and writes `output`, an
// image of the same size whose buffer swarmsim allocated for the element's
// output kind (both null when it gives values: the chain then goes on with
// `input` as kind values). `parameters` are the element's key values in the
// order it declared them. It may write up to max_values numbers (its
// packet, as sim.readVisionSensor returns it) and returns how many, or -1
// after writing a message into `error`: the run stops with it. Sensors of
// different robots run concurrently: keep it thread-safe.
typedef int (*SwarmsimFilterFunction)(const SwarmsimImage* input, SwarmsimImage* output,
                                      const double* parameters, double* values, int max_values,
                                      char* error, size_t error_size, void* user_data);

// A native controller (ABI 6): a models entry's `native_controller: NAME`
// attaches it to each of the entry's robots (their Lua scripts are dropped
// unless `keep_scripts: true`). For each robot, `init` runs when the world
// starts (or the robot is copied at run time), `step` once per step in the
// control phase (after the robot's scripts, if kept; with a main script, on
// each sim.handleChildScripts pass but the sensing one), `cleanup` when the
// world stops or the robot is removed. context->robot is the robot,
// context->script_object its model root (find_object paths such as
// "./leftMotor" are relative to it). Robots run concurrently: touch only
// the robot's own objects and state. init stores the robot's state in
// *state (null is fine); step and cleanup get it back. init and step
// return 0, or -1 after writing a message into `error`: the run stops with
// it, naming the robot and the plugin (or, under on_script_error:
// disable_script, that robot's controller is disabled). No C++ exception
// may leave these functions.
typedef int (*SwarmsimControllerInit)(const SwarmsimCallContext* context, void** state, char* error,
                                      size_t error_size, void* user_data);
typedef int (*SwarmsimControllerStep)(const SwarmsimCallContext* context, void* state, char* error,
                                      size_t error_size, void* user_data);
typedef void (*SwarmsimControllerCleanup)(const SwarmsimCallContext* context, void* state,
                                          void* user_data);

typedef struct SwarmsimRegistrar {
  void* impl;
  // Registers sim.<name>; returns 0, or -1 if the name is taken or invalid.
  int (*add_command)(void* impl, const char* name, const char* description, SwarmsimCommand command,
                     void* user_data);
  // The plugin's name, version and one-line description (swarmsim modules).
  void (*set_info)(void* impl, const char* name, const char* version, const char* description);
  // --- ABI 2 ---
  // Registers a callback for `phase` (SwarmsimPhase); per_robot: see
  // SwarmsimPhaseCallback. Callbacks of one phase run in registration order.
  // Returns 0, or -1 for an unknown phase or a null callback.
  int (*add_phase_callback)(void* impl, int phase, int per_robot, SwarmsimPhaseCallback callback,
                            void* user_data);
  // --- ABI 3 ---
  // Registers the sensor type `name` (see SwarmsimSensorFunction); returns 0,
  // or -1 for a missing name or function.
  int (*add_sensor_type)(void* impl, const char* name, const char* description,
                         SwarmsimSensorFunction sense, void* user_data);
  // --- ABI 4 ---
  // Registers the object type `name`: model files place its objects as
  // {type: NAME, name: ..., KEY: value, ...}, copied, scaled and removed
  // with their model like built-in objects; scripts and callbacks read an
  // object's values through the world API's object_values (a plugin command
  // such as sim.readBeacon(h)). Returns 0, or -1 for a missing or taken
  // name, a key without a name, or a default outside its range.
  int (*add_object_type)(void* impl, const char* name, const char* description,
                         const SwarmsimObjectKey* keys, int key_count);
  // Like add_sensor_type, with readings of up to `max_values` numbers (any
  // size: a scan, an image) instead of SWARMSIM_SENSOR_MAX_VALUES; the sense
  // function gets max_values. Returns -1 for max_values < 1.
  int (*add_sensor_type_of_size)(void* impl, const char* name, const char* description,
                                 int max_values, SwarmsimSensorFunction sense, void* user_data);
  // --- ABI 5 ---
  // Registers the vision-sensor filter element `name`: a sensor's model
  // entry lists it as {type: NAME, KEY: value, ...}. It takes the kinds
  // `input_kinds` (SwarmsimImageKind bits) and gives `output_kind` (one
  // kind; 0: the kind it was given); its keys are numbers (length_power is
  // ignored: images do not scale). max_values: the numbers its packet holds
  // at most (0: it outputs none). Returns 0, or -1 for a missing or taken
  // name, no function, no input kind, or a bad key.
  int (*add_vision_filter)(void* impl, const char* name, const char* description, int input_kinds,
                           int output_kind, const SwarmsimObjectKey* keys, int key_count,
                           int max_values, SwarmsimFilterFunction filter, void* user_data);
  // --- ABI 6 ---
  // Registers the native controller `name` (see SwarmsimControllerInit);
  // init and cleanup may be null. Returns 0, or -1 for a missing or taken
  // name or no step function.
  int (*add_controller)(void* impl, const char* name, const char* description,
                        SwarmsimControllerInit init, SwarmsimControllerStep step,
                        SwarmsimControllerCleanup cleanup, void* user_data);
} SwarmsimRegistrar;

// The two entry points a plugin exports.
int swarmsim_plugin_abi_version(void);
int swarmsim_plugin_register(const SwarmsimRegistrar* registrar);

#ifdef __cplusplus
}  // extern "C"
#endif

#endif  // SWARMSIM_PLUGIN_API_H_
