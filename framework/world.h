// The world: a scene, its calculation modules and its scripts, stepped in
// the five phases of DESIGN.md. A World is an ordinary object owned by its
// caller; one process can hold many.
#pragma once

#include <sched.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "framework/collections.h"
#include "framework/dependent_joints.h"
#include "framework/lazy_vector.h"
#include "framework/messaging.h"
#include "framework/module.h"
#include "framework/parameters.h"
#include "framework/phase_handlers.h"
#include "framework/plugin_api.h"
#include "framework/random.h"
#include "framework/scene.h"
#include "framework/script_memory.h"

namespace swarmsim {

using CalculationModule = Module;  // framework/calculation_module.h
class DynamicsBackend;
struct DynamicsOptions;
class FloorLayer;
class IrAccess;
class LedAccess;
class SensorValueAccess;
class ModuleRegistry;
struct PhaseCallback;
class PluginControllers;
struct PluginControllerType;
struct PluginSensorType;
class LineOfSight;
class ProximityReadings;
class TaskScheduler;
class World;

// What a world does when a script fails (world setting on_script_error).
enum class ScriptErrorPolicy : uint8_t {
  kStop,           // end the run with the error (nonzero exit, outputs so far kept)
  kDisableScript,  // log the error once, disable that script instance, go on
};

struct WorldSettings {
  std::string file;                 // world file, for messages ("" for worlds built in code)
  std::filesystem::path directory;  // folder scripts are resolved against
  std::string physics = "box2d";    // dynamics backend, by registered name
  double time_step = 0.1;           // s, one control step
  int physics_substeps = 10;        // physics steps per control step
  // Arena regions the dynamics steps concurrently: 0 = auto (chosen from the
  // scene, never from the thread count), N = that many; 1 = one engine world.
  int physics_partitions = 1;
  uint64_t seed = 1;
  int threads = 0;                  // <= 0: all cores
  double gravity = 9.81;            // m/s^2
  double octree_resolution = 0.05;  // m
  // The backend's own settings (`simulation: {ode: {...}}`, read by the
  // section it registered), or null: its defaults.
  std::shared_ptr<const DynamicsOptions> physics_options;
  // The world's own main script (null: the default step). Its sysCall_step
  // runs the phases through sim.handleSensing(), sim.handleChildScripts(), ...
  std::shared_ptr<const ScriptSource> main_script;
  // Lua instructions one non-threaded callback may run before it is stopped
  // with an error (0: no limit).
  int64_t instruction_budget = 100'000'000;
  // Bytes one robot's scripts (or the scene's scripts and the main script)
  // may hold, their Lua memory and the data sim.* calls keep for them
  // (framework/script_memory.h), before a script fails with an error (0: no
  // limit).
  int64_t script_memory_limit = int64_t{256} << 20;
  // Robots whose scripts share one Lua state (1: a state each). Robots
  // r / n share; each keeps its own environments, math.random generator,
  // required modules and context, so well-behaved scripts give the same
  // results as with a state each, in less memory (their compiled functions,
  // libraries and sim table once per state). script_memory_limit then
  // applies to a state as n times the limit.
  int robots_per_lua_state = 1;
  // Bytes every script of the run may hold together (0: no limit): 20
  // robots x 256 MiB would otherwise be 5 GiB. Negative (the default): set
  // at Start, kDefaultRunScriptMemory or kRunScriptMemoryPerRobot a robot,
  // whichever is more (a robot's Lua state alone takes ~16 KiB).
  int64_t run_script_memory_limit = -1;
  static constexpr int64_t kDefaultRunScriptMemory = int64_t{4} << 30;
  static constexpr int64_t kRunScriptMemoryPerRobot = int64_t{64} << 10;
  // Bytes the whole process may hold (swarmsim run --max-memory; 0: what
  // the machine has): a world whose robot copies or Lua states will not fit
  // is refused while they are built (framework/memory_forecast.h).
  uint64_t max_memory = 0;
  // Wall-clock seconds one step (or the start or stop of the world) may take
  // before the runner ends the run as stuck, naming the script calls in
  // progress (0: no limit). A safety net for what the instruction budget
  // cannot stop: a script inside one C function (e.g. a pattern match that
  // backtracks). It does not change results: it only ends runs.
  double step_timeout = 60;
  ScriptErrorPolicy on_script_error = ScriptErrorPolicy::kStop;
  // Sandbox (framework/lua_sandbox.cc): scripts may read files under
  // `directory` and write files under `output_directory` (the run's --out;
  // empty: no writing). trust_scripts (--trust-scripts) gives them Lua's
  // full standard libraries instead.
  std::filesystem::path output_directory;
  bool trust_scripts = false;
};

// A value recorded by a script (sim.recordMetric) or by an observer.
struct MetricSample {
  int64_t step = 0;
  double time = 0;
  int instance = -1;  // robot index, -1 for swarm-level metrics
  std::string name;
  double value = 0;
};

// A write by one robot's script to another robot's object, applied after the
// control phase in handle order.
struct DeferredWrite {
  // kShapeDynamic: value 1 makes the shape dynamic, 0 kinematic (sim.setObjectDynamic).
  // kObjectPose: the object moves to world pose `pose` (sim.setObjectPose/Position).
  // kSizeFactor: the object's subtree is rescaled so that its size factor
  // becomes `value` (sim.setObjectSizeFactor, Scene::ScaleSubtree).
  // kJointPosition: a non-simulated joint jumps to `value` (sim.setJointPosition).
  enum class Kind : uint8_t {
    kJointTargetVelocity,
    kJointTargetPosition,
    kJointPosition,
    kShapeDynamic,
    kObjectPose,
    kSizeFactor
  };
  ObjectId object;
  Kind kind;
  double value;
  Pose pose = {};
};

// Per-robot runtime state. Only the worker running that robot touches it
// during a phase; the world merges the buffers after the phase, in robot order.
// Lines a robot's scripts printed during the phase, in order. Its robot's
// worker appends and the main thread drains it after the phase; the run's
// watchdog may drain it from its own thread when a step never ends, so that
// what was printed before is not lost. Hence the lock (never contended
// outside that case).
class LogBuffer {  // 16 bytes: one per robot
 public:
  LogBuffer() = default;
  LogBuffer(LogBuffer&& other) noexcept : lines_(std::move(other.lines_)) {}
  LogBuffer& operator=(LogBuffer&& other) noexcept {
    const std::lock_guard lock(mutex_);
    lines_ = std::move(other.lines_);
    return *this;
  }
  void Add(std::string line) {
    const std::lock_guard lock(mutex_);
    lines_.push_back(std::move(line));
  }
  bool empty() const {
    const std::lock_guard lock(mutex_);
    return lines_.empty();
  }
  // Hands every line to sink(std::string_view) in order and empties the buffer.
  template <typename Sink>
  void Drain(const Sink& sink) {
    const std::lock_guard lock(mutex_);
    for (const std::string& line : lines_) sink(line);
    lines_.clear();
  }

 private:
  // A one-byte lock: uncontended but for the watchdog's drain.
  class SpinLock {
   public:
    void lock() {
      while (flag_.test_and_set(std::memory_order_acquire)) sched_yield();
    }
    void unlock() { flag_.clear(std::memory_order_release); }

   private:
    std::atomic_flag flag_ = ATOMIC_FLAG_INIT;
  };
  mutable SpinLock mutex_;
  LazyVector<std::string> lines_;
};

// A copy or removal of a robot asked for by a script (sim.copyModel,
// sim.removeModel, lua_api_models.cc), applied by the World between the
// control and actuate phases (World::ApplyModelEdits, world_model_edits.cc).
struct ModelEdit {
  // kAdd: objects a module's Lua call makes (sim.createPath), `add` run on
  // the scene after the copies and removals, in the same order.
  enum class Kind : uint8_t { kCopy, kRemove, kAdd };
  Kind kind = Kind::kCopy;
  std::function<void(Scene*)> add;  // kAdd
  ObjectId root;                    // the robot's model root (validated when queued)
  bool has_pose = false;  // kCopy: place the copy at (x, y, yaw), else at the source's pose
  double x = 0, y = 0;    // m, world frame
  double yaw = 0;         // rad
  // kCopy: bytes taken from the run's script memory at the call, handed to
  // the copy's account when it is made, given back if it is not.
  uint64_t charged = 0;
};
// Copies and removals one script state may queue between two applications
// (one step): a clear error past it, so a runaway loop cannot exhaust memory.
inline constexpr size_t kMaxModelEditsPerStep = 1000;

struct RobotRuntime {
  // First, side by side: what the World looks at after every robot's
  // control (World::PendingBits), 96 bytes, so that a robot whose
  // controller left them empty costs two cache lines, not three or four.
  LogBuffer log;                      // lines printed during the phase
  std::vector<MetricSample> metrics;  // samples recorded this step
  // The lists most robots never fill take 8 bytes until used (lazy_vector.h).
  LazyVector<DeferredWrite> deferred;  // writes to other robots' objects
  LazyVector<ModelEdit> model_edits;   // copies and removals of robots, call order
  LazyVector<std::string> disabled;    // scripts disabled this phase (disable_script), why
  std::string error;                   // a script error in this phase
  Rng rng;
  SharedParameters parameters;  // the instance's model parameters
  // Bytes of `log` and `metrics` charged to the robot's ScriptMemory,
  // released when the world takes them; bytes printed in step print_step.
  uint64_t log_bytes = 0, metric_bytes = 0;
  uint64_t printed_bytes = 0;
  int64_t print_step = -1;
  LazyVector<CollectionRow> collections;  // the scripts' own (sim.createCollection)
  // Bytes charged to the robot's ScriptMemory for its lifetime: its
  // collections and the objects its scripts made (sim.createPath), released
  // when it is removed.
  uint64_t lifetime_bytes = 0;
  // Its messages, signal and custom-data writes: Messaging::robot_mail.
};

// A module that observes the world in the record phase (swarm metrics,
// the paint layer; framework/module.h).
using Observer = Module;

// Robots per task in the parallel phases (and module hooks that fan out over
// robots): big enough to amortise the task overhead (a robot's sense +
// control is a few microseconds), small enough to balance two to eight workers.
inline constexpr int64_t kRobotGrain = 8;

// Wall-clock seconds spent in each phase (framework/phase.h), summed over the run.
using PhaseTimes = std::array<double, kPhaseCount>;

class World final : public PhaseHandlers {
 public:
  World(const WorldSettings& settings, const ModuleRegistry& registry);
  // Same, keeping `registry` alive as long as the world (a world file's
  // plugins register into a registry of the world's own).
  World(const WorldSettings& settings, std::shared_ptr<const ModuleRegistry> registry);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const WorldSettings& settings() const { return settings_; }
  Scene& scene() { return scene_; }
  const Scene& scene() const { return scene_; }

  // --- Parameters ---------------------------------------------------------------
  ParameterSet& parameters() { return parameters_; }
  const ParameterSet& parameters() const { return parameters_; }
  // A parameter as a script sees it: the robot's model parameter if it has
  // one of that name, else the world parameter. Null if neither exists.
  const ParamValue* FindParameter(int instance, std::string_view name) const;
  // Sets the model parameters of a robot (call after the robot is created).
  void SetInstanceParameters(int instance, SharedParameters parameters);
  // The same for a value set after load (Python's World.set_param): from
  // then on the robot's parameters are part of the state hash and of
  // snapshots (world_writes.cc). Worlds nobody writes to hash as before.
  void WriteInstanceParameters(int instance, SharedParameters parameters);
  // Room for `robots` robots in all (a loader about to add many): their
  // per-robot state then grows without slack. With `prefault`, the room is
  // added to it (framework/prefault.h), for the caller to populate.
  void ReserveRobots(size_t robots, Prefault* prefault = nullptr);

  // --- Lifecycle ------------------------------------------------------------------
  // Builds the dynamics backend and the modules from the placed scene and runs
  // every script's sysCall_init. Throws swarmsim::Error on bad input. On a
  // script error, Start, Step and Stop first pass what every robot printed
  // to the log sink, in robot order.
  void Start();
  // Called as Start() begins each of its stages, with the stage's name
  // ("world poses", "physics (planar)", "module proximity", "scripts (Lua
  // states, sysCall_init)", "native controllers' init"), and with "" when it
  // has started: a large world's start takes seconds, and the command line
  // says which part it is in.
  void set_start_progress(std::function<void(const std::string& stage)> progress) {
    start_progress_ = std::move(progress);
  }
  // Called by Start() before each stage and between its robots' Lua states
  // (on any thread): throws to end the start (a run's stop signal: a
  // million robots' start takes seconds). Null: none.
  void set_stop_check(std::function<void()> check) { stop_check_ = std::move(check); }
  void CheckStop() const {
    if (stop_check_) stop_check_();
  }
  // One control step: sense, control, actuate, physics, record. Throws
  // swarmsim::Error on a script error or a non-finite physics state; the
  // world is then stopped and may not be stepped again.
  void Step();
  // Runs sysCall_cleanup. Called by the destructor if not called before.
  void Stop();
  bool started() const { return started_; }

  int64_t step_count() const { return step_count_; }
  double time() const { return time_; }
  // Robot indices in use: every model instance ever made, removed ones
  // included (indices are never reused; ModelInstance::alive tells).
  int robot_count() const;
  // Robots not removed.
  int live_robot_count() const;
  int threads() const;

  // Hash of every object's pose and velocity, joint states, sensor
  // readings, random streams and time. Equal hashes, equal futures.
  uint64_t StateHash() const;

  // Sets the velocities of robots between steps (Python's World.set_velocities;
  // world_writes.cc): robot robots[i]'s root moves at v_W[i] (m/s) turning at
  // w_W[i] (rad/s, world frame), and every shape on it with the same rigid
  // motion. The dynamics backend takes them at the next step
  // (DynamicsBackend::TakeVelocities). Throws swarmsim::Error, before
  // setting anything, for a robot whose root is not a shape or that was removed.
  void SetVelocities(std::span<const int> robots, std::span<const Vec3> v_W,
                     std::span<const Vec3> w_W);

  // --- Snapshots (framework/world_state.h, world_state.cc) ---------------------------------
  // The world's state as bytes: restore + k steps gives the state of k more
  // steps from here. Starts the world if it has not started, and rebuilds
  // the dynamics engine from the scene (world_state.h: why). Throws
  // swarmsim::Error naming what cannot be saved (a robot's Lua script, a
  // native controller, a module or type without save hooks). `taken`:
  // samples TakeMetrics already handed out that the state carries too, ahead
  // of those not yet taken (swarmsim run passes its metrics.csv's rows, so
  // that the run resumed from the state writes the whole history).
  std::string SaveState(std::span<const MetricSample> taken = {});
  // Puts the world in the state `bytes` hold (from SaveState of a world
  // loaded from the same file and settings, any seed). Throws
  // swarmsim::Error for bytes of another world, corrupt or truncated ones,
  // before changing anything. With `reseed`, the bytes of a world that has
  // not stepped become that world as a load with `reseed->seed` makes it:
  // that seed, its random streams, and the robots' root poses the loader
  // placed with it (LoadedWorld::placement): World.reset(seed).
  struct Reseed {
    uint64_t seed = 0;
    std::span<const std::pair<int, Pose>> roots;  // (robot index, root world pose)
  };
  void RestoreState(std::string_view bytes, const Reseed* reseed = nullptr);
  // Why SaveState would refuse this world, or "" if it would not.
  std::string SnapshotRefusal() const;

  // --- Outputs ----------------------------------------------------------------------
  // Script `print` lines are passed here, prefixed by the robot instance
  // name, in robot order after each phase. Default: standard output.
  void set_log_sink(std::function<void(std::string_view)> sink) { log_sink_ = std::move(sink); }
  // The process ends soon after this world stops (swarmsim run): Stop leaves
  // the scripts' Lua states that could run no code as they close (no io
  // file, sandboxed) to the system instead of freeing them object by object.
  void set_process_ends_after_stop(bool ends) { process_ends_after_stop_ = ends; }
  bool process_ends_after_stop() const { return process_ends_after_stop_; }
  // For the plugins' world API (record_metric): a metrics row of this step
  // for `robot` (-1: swarm-level), from the record phase's plugin callbacks
  // only (any thread). False outside that phase, for a bad robot or an
  // empty name.
  bool RecordPluginMetric(int robot, std::string_view name, double value);
  // Whether `name` is a swarm metric this world's metrics: list records: a
  // robot's or plugin's metric may not take it (its rows would join that one).
  bool IsListedSwarmMetric(std::string_view name) const;
  // For a step that never ends (the runner's watchdog thread): hands what
  // the scripts printed in it so far to the log sink, robots in index order,
  // then the scene's scripts.
  void FlushPrintsOfStuckStep();
  void Log(std::string_view line) const;
  // --- Modules (framework/module.h) --------------------------------------------------
  // The world's instance of the module registered as `name`, made on first
  // use (with no configuration) and run from then on. Call before the model
  // copies it serves are duplicated, so it follows them. Throws
  // swarmsim::Error for an unknown name.
  Module* module(std::string_view name);
  // Null if the world has no instance of it.
  Module* find_module(std::string_view name) const;
  // Adds an instance of the module registered as `name`, made with `config`
  // (what its descriptor's `make` expects: a `paint:` section's settings, a
  // metric's `every`); a module may have several. Returns it.
  Module* AddModule(std::string_view name, const void* config);
  // The names of the world's modules, in creation order, then those every
  // world gets when it starts (proximity) if it has not started.
  std::vector<std::string> module_names() const;
  // Every module's CheckReferences (the loader, once the world's objects
  // exist), in creation order.
  void CheckModuleReferences();
  // Adds a record-phase module made by the caller, not registered (tests,
  // embedders), after the registered ones.
  void AddObserver(std::unique_ptr<Observer> observer);
  // Every module's WriteOutputs(dir), in creation order.
  void WriteOutputs(const std::filesystem::path& dir) const;
  // Every module's ListOutputs, in creation order.
  std::vector<OutputFile> ListOutputs() const;
  // Metric samples recorded since the last call, in (step, robot, order) order.
  std::vector<MetricSample> TakeMetrics();
  // How many times TakeMetrics has been called: a module whose Record reads
  // the samples so far (the recorder) knows by it when they were taken.
  uint64_t metrics_taken() const { return metrics_taken_; }
  // Scripts disabled under on_script_error: disable_script so far, each with
  // its error (robot order within a step, then the scene's).
  const std::vector<std::string>& disabled_scripts() const { return disabled_scripts_; }
  const PhaseTimes& phase_times() const { return phase_times_; }

  // --- For modules and the script host -----------------------------------------------
  RobotRuntime& runtime(int instance) { return runtimes_.at(instance); }
  RobotRuntime& scene_runtime() { return scene_runtime_; }
  TaskScheduler& scheduler() { return *scheduler_; }
  const ModuleRegistry& registry() const { return registry_; }
  DynamicsBackend* dynamics() { return dynamics_.get(); }
  // Is a segment clear of the static environment (framework/line_of_sight.h:
  // range messages with line of sight, blob cameras' occlusion)? Provided by
  // a module when it starts (proximity); null: nothing blocks.
  const LineOfSight* line_of_sight() const { return line_of_sight_; }
  void set_line_of_sight(const LineOfSight* service) { line_of_sight_ = service; }
  // What proximity sensors read (framework/proximity_readings.h: the
  // plugins' C API). Provided by a module when it starts (proximity); null:
  // no object is a proximity sensor.
  const ProximityReadings* proximity_readings() const { return proximity_readings_; }
  void set_proximity_readings(const ProximityReadings* service) { proximity_readings_ = service; }
  ScriptHost* scripts() { return scripts_.get(); }
  // The floor image a module keeps (framework/floor_layer.h: the paint
  // layer), or null; its provider sets it and outlives the world's use of it.
  const FloorLayer* floor_layer() const { return floor_layer_; }
  void set_floor_layer(const FloorLayer* layer) { floor_layer_ = layer; }
  // What robot `instance`'s scripts hold (-1: the scene's scripts and the
  // main script), and the run's whole (framework/script_memory.h).
  ScriptMemory& script_memory(int instance) {
    return instance < 0 ? scene_script_memory_ : robot_script_memory_.at(instance);
  }
  const RunScriptMemory& run_script_memory() const { return run_script_memory_; }
  // module(name) / find_module(name), by their old names.
  CalculationModule* calculation(const std::string& name) { return module(name); }
  CalculationModule* find_calculation(const std::string& name) const { return find_module(name); }
  size_t script_memory_bytes() const;

  // --- Main-script handlers (PhaseHandlers) ---------------------------------------------
  // The phases of the default step, for a world's own main script
  // (sim.handleSensing(), ...). Robots fan out in parallel inside each.
  void HandleSensing() override;
  void HandleChildScripts(ScriptPass pass) override;
  void HandleActuation() override;
  void HandleDynamics() override;

  // --- Plugin sensors (framework/plugin_api.h) -------------------------------------------
  // The last reading of plugin sensor `id` into *values: false before its
  // first sense. Throws swarmsim::Error if `id` is not a plugin sensor.

  // --- Native controllers (framework/plugin_controllers.h) -------------------------------
  // Robot `robot` runs the plugin controller `type` (a models entry's
  // native_controller:) from Start on; copies made at run time inherit it.
  // in_place_of_scripts: its model's Lua scripts were dropped for it
  // (PluginControllers::Assign).
  void SetNativeController(int robot, const PluginControllerType* type, bool in_place_of_scripts);
  // Null when no robot has one.
  PluginControllers* plugin_controllers() { return controllers_.get(); }
  // The device services of the plugins' world API (framework/device_access.h),
  // found once when the world starts (null without the module, and before).
  struct DeviceServices {
    const SensorValueAccess* light = nullptr;   // the "light" module's
    const SensorValueAccess* ground = nullptr;  // the "ground_sensor" module's
    const LedAccess* leds = nullptr;            // the "blobs" module's
    const IrAccess* ir = nullptr;               // the "ir_messaging" module's
  };
  const DeviceServices& device_services() const { return device_services_; }

  // --- Messages and signals ------------------------------------------------------------
  // Delivered at the start of each step; signal writes applied when a
  // control pass ends.
  Messaging& messaging() { return messaging_; }
  const Messaging& messaging() const { return messaging_; }

 private:
  void Sense();
  void Control(ScriptPass pass = ScriptPass::kAll);
  void Actuate();
  void Physics();
  void Record();
  void RunModules(Phase phase);
  void EnsureRuntimes();
  // Copies and removals the scripts queued (RobotRuntime::model_edits),
  // robots in index order then the scene's, call order within each: every
  // copy first (new robots, their sysCall_init), then every removal (its
  // sysCall_cleanup, then its objects). world_model_edits.cc.
  void ApplyModelEdits();
  ObjectId CopyRobot(const ModelEdit& edit);
  void RemoveRobot(ObjectId root);
  void FlushRobotBuffers();
  // Hands rt's printed lines to the log sink and releases their bytes.
  void DrainLog(RobotRuntime& rt, ScriptMemory& memory);
  // The scene's scripts' prints and metrics (a main script's, after its step).
  void FlushSceneBuffers();
  // After an error escaped the scripts: what every robot and the scene
  // printed (and recorded) before it, in robot order. The error in flight is
  // the one reported: the buffers' own are dropped. Not for the hot path.
  void FlushBuffersAfterError() noexcept;
  // Plugin phase callbacks at that edge of the phase; nothing at all when none
  // is registered.
  void RunPhaseCallbacks(Phase phase, PhaseEdge edge) {
    if (!CallbacksAt(phase, edge).empty()) CallPhaseCallbacks(CallbacksAt(phase, edge));
  }
  std::vector<const PhaseCallback*>& CallbacksAt(Phase phase, PhaseEdge edge) {
    return phase_callbacks_[static_cast<size_t>(phase) * 2 + static_cast<size_t>(edge)];
  }
  void CallPhaseCallbacks(const std::vector<const PhaseCallback*>& callbacks);
  // world_state.cc: the fingerprint parts a snapshot carries, and the
  // dynamics rebuilt from the scene.
  void WriteFingerprint(StateWriter* out) const;
  void CheckFingerprint(StateReader* in) const;
  void RebuildDynamics();
  // world_writes.cc: the parameters written after load, in the hash and in snapshots.
  void HashWrittenParameters(StateHasher* hasher) const;
  void SaveWrittenParameters(StateWriter* out) const;
  void LoadWrittenParameters(StateReader* in);
  // Robots whose parameters were written after load (WriteInstanceParameters),
  // with their parameters as loaded (what a restore without them puts back).
  std::map<int, SharedParameters> loaded_parameters_;
  // The world file's content hash, read at the first snapshot or restore
  // (0: no file, or unreadable).
  mutable uint64_t file_hash_ = 0;
  mutable bool file_hashed_ = false;
  WorldSettings settings_;
  const ModuleRegistry& registry_;
  std::shared_ptr<const ModuleRegistry> owned_registry_;  // null unless given by shared_ptr
  // What the scripts hold: first, so that they outlive the scene (custom
  // data blocks), the messages and the script states that charge them.
  RunScriptMemory run_script_memory_;
  std::deque<ScriptMemory> robot_script_memory_;  // by robot (stable addresses)
  ScriptMemory scene_script_memory_;
  std::array<std::vector<const PhaseCallback*>, kPhaseCount * 2>
      phase_callbacks_;  // by (phase, edge): CallbacksAt
  // Rows plugins record in the record phase (RecordPluginMetric).
  bool recording_ = false;
  std::mutex plugin_metrics_mutex_;
  std::vector<MetricSample> plugin_metrics_;
  Scene scene_;
  DependentJoints dependent_joints_;  // joints following a master, in order
  ParameterSet parameters_;
  std::unique_ptr<TaskScheduler> scheduler_;
  std::unique_ptr<DynamicsBackend> dynamics_;
  const LineOfSight* line_of_sight_ = nullptr;             // owned by the module that provides it
  const ProximityReadings* proximity_readings_ = nullptr;  // the same
  std::function<void(const std::string&)> start_progress_;
  std::function<void()> stop_check_;
  void StartStage(const std::string& stage) const {
    if (start_progress_) start_progress_(stage);
  }
  std::unique_ptr<ScriptHost> scripts_;
  const FloorLayer* floor_layer_ = nullptr;  // owned by its module
  DeviceServices device_services_;
  std::unique_ptr<PluginControllers> controllers_;  // null: no robot has a native controller
  std::vector<RobotRuntime> runtimes_;
  // Per robot, which of its RobotRuntime buffers may hold something (kPending*
  // bits, world.cc): the serial passes between phases visit only those
  // robots instead of touching 10,000 runtimes to find them empty.
  std::vector<uint8_t> pending_;
  // (Messaging keeps its own for the robots' mail.)
  static constexpr uint8_t kPendingOutput = 1;         // log, metrics, error
  static constexpr uint8_t kPendingDeferred = 2;       // deferred writes
  static constexpr uint8_t kPendingModelEdits = 4;     // copies and removals of robots
  static uint8_t PendingBits(const RobotRuntime& rt);  // what rt's buffers hold
  void MarkAllPending();
  RobotRuntime scene_runtime_;
  // The world's modules in creation order, and by phase in run order.
  struct ModuleEntry {
    std::string name;
    int order = 0;
    uint32_t phases = 0;
    std::unique_ptr<Module> instance;
  };
  std::vector<ModuleEntry> modules_;
  std::array<std::vector<Module*>, kPhaseCount> modules_by_phase_;
  Module* InstallModule(std::string name, int order, uint32_t phases,
                        std::unique_ptr<Module> instance);
  // Start's stages up to the scripts: poses, physics, modules.
  void StartParts(const std::function<void(const std::string&)>& stage);
  std::vector<MetricSample> metrics_;
  uint64_t metrics_taken_ = 0;
  std::vector<std::string> disabled_scripts_;
  std::function<void(std::string_view)> log_sink_;
  PhaseTimes phase_times_{};
  Messaging messaging_;
  bool dynamics_handled_ = false;  // sim.handleDynamics() ran this step
  int64_t step_count_ = 0;
  double time_ = 0;
  bool started_ = false;
  bool stopped_ = false;
  bool failed_ = false;
  bool start_failed_ = false;  // Start threw before the scripts: physics, modules half built
  bool process_ends_after_stop_ = false;
};

}  // namespace swarmsim
