#include "framework/world.h"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <utility>

#include "framework/calculation_module.h"
#include "framework/device_access.h"
#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/line_of_sight.h"
#include "framework/memory_forecast.h"
#include "framework/object_type.h"
#include "framework/plugin_controllers.h"
#include "framework/prefault.h"
#include "framework/registry.h"
#include "framework/scheduler.h"
#include "framework/state_hash.h"
#include "framework/suggest.h"
#include "framework/utf8.h"

namespace swarmsim {

namespace {

class PhaseTimer {
 public:
  explicit PhaseTimer(double* total) : total_(total), start_(std::chrono::steady_clock::now()) {}
  ~PhaseTimer() {
    *total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  double* total_;
  std::chrono::steady_clock::time_point start_;
};

bool IsFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool IsFinite(const Pose& X) {
  return std::isfinite(X.p.x) && std::isfinite(X.p.y) && std::isfinite(X.p.z) &&
         std::isfinite(X.q.w) && std::isfinite(X.q.x) && std::isfinite(X.q.y) &&
         std::isfinite(X.q.z);
}

// Every object's world pose from its parent's: each robot's subtree on its
// own worker, then the scene's objects (all in one pass when some robot hangs
// from another or from a scene object).
void UpdateWorldPoses(Scene* scene, TaskScheduler& scheduler) {
  if (!scene->InstancesAreIndependent()) return scene->UpdateWorldPoses();
  const int64_t n = static_cast<int64_t>(scene->instances().size());
  scheduler.ParallelFor(0, n, kRobotGrain, [&](int64_t begin, int64_t end) {
    for (int64_t r = begin; r < end; ++r)
      if (scene->instances()[r].alive) scene->UpdateWorldPoses(static_cast<int>(r));
  });
  scene->UpdateSceneObjectPoses();
}

}  // namespace

const char* ToString(Phase phase) {
  switch (phase) {
    case Phase::kSense: return "sense";
    case Phase::kControl: return "control";
    case Phase::kActuate: return "actuate";
    case Phase::kPhysics: return "physics";
    case Phase::kRecord: return "record";
    case Phase::kCount: break;
  }
  return "?";
}

std::string ShowParamValue(const ParamValue& value) {
  if (const double* d = std::get_if<double>(&value)) {
    char buf[32];
    // Whole numbers as written (100000, not the shortest form 1e+05).
    if (*d == std::floor(*d) && std::abs(*d) < 1e15) {
      const auto whole = std::to_chars(buf, buf + sizeof buf, static_cast<int64_t>(*d));
      return std::string(buf, whole.ptr);
    }
    const auto result = std::to_chars(buf, buf + sizeof buf, *d);
    return std::string(buf, result.ptr);
  }
  return ParamToString(value);
}

std::string ParamToString(const ParamValue& value) {
  if (const double* d = std::get_if<double>(&value)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", *d);
    return buf;
  }
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  return std::get<std::string>(value);
}

World::World(const WorldSettings& settings, const ModuleRegistry& registry)
    : settings_(settings),
      registry_(registry),
      scheduler_(std::make_unique<TaskScheduler>(settings.threads)),
      log_sink_([](std::string_view line) {
        // A script may print any bytes; the console gets UTF-8.
        const std::string valid = IsValidUtf8(line) ? std::string() : ValidUtf8(line);
        if (!valid.empty()) line = valid;
        std::fwrite(line.data(), 1, line.size(), stdout);
        std::fputc('\n', stdout);
      }) {
  if (!(settings_.time_step > 0) || !std::isfinite(settings_.time_step))
    throw Error("time step must be a positive number of seconds");
  if (settings_.physics_substeps < 1) throw Error("physics substeps must be at least 1");
  run_script_memory_.set_limit(static_cast<uint64_t>(settings_.run_script_memory_limit < 0
                                                         ? WorldSettings::kDefaultRunScriptMemory
                                                         : settings_.run_script_memory_limit));
  scene_script_memory_.Attach(&run_script_memory_, static_cast<uint64_t>(std::max<int64_t>(
                                                       settings_.script_memory_limit, 0)));
  messaging_.scene_mail().memory = &scene_script_memory_;
  // Validate the backend name now, so a typo fails before any work is done.
  if (!registry_.HasDynamics(settings_.physics)) registry_.MakeDynamics(settings_.physics);
  for (const PhaseCallback& callback : registry_.phase_callbacks())
    CallbacksAt(callback.phase, callback.edge).push_back(&callback);
  // Object types of modules and plugins, after the built-in ones.
  for (const ObjectTypeDescriptor* type : registry_.object_types()) scene_.RegisterType(*type);
}

World::World(const WorldSettings& settings, std::shared_ptr<const ModuleRegistry> registry)
    : World(settings, *registry) {
  owned_registry_ = std::move(registry);
}

World::~World() {
  try {
    Stop();
  } catch (...) {
    // A failing sysCall_cleanup cannot be reported from a destructor.
  }
}

int World::robot_count() const { return static_cast<int>(scene_.instances().size()); }
int World::threads() const { return scheduler_->threads(); }

void World::Log(std::string_view line) const { log_sink_(line); }

void World::FlushPrintsOfStuckStep() {
  for (RobotRuntime& rt : runtimes_) rt.log.Drain(log_sink_);
  scene_runtime_.log.Drain(log_sink_);
}

Module* World::InstallModule(std::string name, int order, uint32_t phases,
                             std::unique_ptr<Module> instance) {
  if (phases & PhaseBit(Phase::kControl))
    throw Error("module '" + name + "' hooks the control phase, which is the scripts' own");
  Module* module = instance.get();
  modules_.push_back({std::move(name), order, phases, std::move(instance)});
  scene_.AddListener(module);
  // Each phase's list in (order, creation) order.
  for (size_t p = 0; p < modules_by_phase_.size(); ++p) {
    if (!(phases & PhaseBit(static_cast<Phase>(p)))) continue;
    std::vector<Module*>& list = modules_by_phase_[p];
    auto at = list.end();
    while (at != list.begin()) {
      const Module* before = *(at - 1);
      const auto entry = std::find_if(modules_.begin(), modules_.end(), [&](const ModuleEntry& e) {
        return e.instance.get() == before;
      });
      if (entry->order <= order) break;
      --at;
    }
    list.insert(at, module);
  }
  if (started_) module->Start(this);
  return module;
}

Module* World::module(std::string_view name) {
  if (Module* existing = find_module(name)) return existing;
  return AddModule(name, nullptr);
}

std::vector<std::string> World::module_names() const {
  std::vector<std::string> names;
  for (const ModuleEntry& e : modules_) names.push_back(e.name);
  if (!started_)
    for (const auto& descriptor : registry_.module_descriptors())
      if (descriptor->every_world) names.push_back(descriptor->info.name);
  return names;
}

void World::CheckModuleReferences() {
  for (ModuleEntry& e : modules_) e.instance->CheckReferences(scene_);
}

Module* World::find_module(std::string_view name) const {
  for (const ModuleEntry& e : modules_)
    if (e.name == name) return e.instance.get();
  return nullptr;
}

Module* World::AddModule(std::string_view name, const void* config) {
  const ModuleDescriptor* descriptor = registry_.FindModule(name);
  if (descriptor == nullptr) {
    std::vector<std::string> known;
    for (const auto& d : registry_.module_descriptors()) known.push_back(d->info.name);
    throw Error("unknown module '" + std::string(name) + "'" + Suggest(name, known));
  }
  return InstallModule(descriptor->info.name, descriptor->order, descriptor->phases,
                       descriptor->make(this, config));
}

void World::AddObserver(std::unique_ptr<Observer> observer) {
  InstallModule("observer", 1000, PhaseBit(Phase::kRecord), std::move(observer));
}

void World::RunModules(Phase phase) {
  for (Module* module : modules_by_phase_[static_cast<size_t>(phase)]) {
    switch (phase) {
      case Phase::kSense: module->Sense(this); break;
      case Phase::kActuate: module->Actuate(this); break;
      case Phase::kPhysics: module->AfterPhysics(this); break;
      case Phase::kRecord: module->Record(*this, &metrics_); break;
      case Phase::kControl:  // refused by InstallModule
      case Phase::kCount: break;
    }
  }
}

void World::WriteOutputs(const std::filesystem::path& dir) const {
  for (const ModuleEntry& e : modules_) e.instance->WriteOutputs(dir);
}

std::vector<OutputFile> World::ListOutputs() const {
  std::vector<OutputFile> files;
  for (const ModuleEntry& e : modules_) e.instance->ListOutputs(&files);
  return files;
}

std::vector<MetricSample> World::TakeMetrics() {
  std::vector<MetricSample> out;
  out.swap(metrics_);
  ++metrics_taken_;
  // In step order, whatever order the scripts and observers recorded in
  // (already sorted in the usual case: then no sort).
  const auto by_step = [](const MetricSample& a, const MetricSample& b) { return a.step < b.step; };
  if (!std::is_sorted(out.begin(), out.end(), by_step))
    std::stable_sort(out.begin(), out.end(), by_step);
  return out;
}

size_t World::script_memory_bytes() const { return scripts_ ? scripts_->MemoryBytes() : 0; }

const ParamValue* World::FindParameter(int instance, std::string_view name) const {
  if (instance >= 0 && instance < static_cast<int>(runtimes_.size()) &&
      runtimes_[instance].parameters) {
    const ParameterSet& own = *runtimes_[instance].parameters;
    if (auto it = own.find(name); it != own.end()) return &it->second;
  }
  if (auto it = parameters_.find(name); it != parameters_.end()) return &it->second;
  return nullptr;
}

void World::EnsureRuntimes() {
  // One runtime per robot, its random stream keyed by (seed, robot index).
  // The scene runtime uses stream 2^63 so it never collides with a robot.
  while (runtimes_.size() < scene_.instances().size()) {
    RobotRuntime r;
    r.rng = Rng(settings_.seed, runtimes_.size());
    runtimes_.push_back(std::move(r));
  }
  pending_.resize(runtimes_.size(), 0xff);  // new robots: look at everything once
  messaging_.Resize(static_cast<int>(runtimes_.size()));
  // Each robot's memory account, which its mail charges too.
  while (robot_script_memory_.size() < runtimes_.size()) {
    robot_script_memory_.emplace_back().Attach(
        &run_script_memory_,
        static_cast<uint64_t>(std::max<int64_t>(settings_.script_memory_limit, 0)));
    const int robot = static_cast<int>(robot_script_memory_.size()) - 1;
    messaging_.robot_mail(robot).memory = &robot_script_memory_.back();
  }
  // (Before Start only: robots copied later must not restart the scene's stream.)
  if (!started_) scene_runtime_.rng = Rng(settings_.seed, uint64_t{1} << 63);
}

void World::ReserveRobots(size_t robots, Prefault* prefault) {
  runtimes_.reserve(robots);
  pending_.reserve(robots);
  messaging_.Reserve(robots);
  if (prefault != nullptr) prefault->AddSpare(runtimes_);
}

void World::SetInstanceParameters(int instance, SharedParameters parameters) {
  EnsureRuntimes();
  runtimes_.at(instance).parameters = std::move(parameters);
}

void World::StartParts(const std::function<void(const std::string&)>& stage) {
  stage("world poses");
  EnsureRuntimes();
  // Dependent joints start where their masters put them, before the engine
  // is built from the scene (ODE built a mimic finger where the file had it).
  dependent_joints_.Apply(&scene_, true);
  UpdateWorldPoses(&scene_, *scheduler_);
  stage("physics (" + settings_.physics + ")");
  dynamics_ = registry_.MakeDynamics(settings_.physics);
  DynamicsSettings dynamics_settings;
  dynamics_settings.gravity = settings_.gravity;
  dynamics_settings.partitions = settings_.physics_partitions;
  dynamics_settings.scheduler = scheduler_.get();
  dynamics_settings.options = settings_.physics_options;
  dynamics_->Build(scene_, dynamics_settings);
  dynamics_->MarkSimulatedJoints(&scene_);
  if (dependent_joints_.Apply(&scene_, true)) scene_.UpdateWorldPoses();  // their targets
  // The modules every world has (proximity), in registration order; then
  // every module starts, in creation order: first those that act on the
  // world, then those that only observe it (the record phase's: graphs,
  // metrics, the recording, snapshots and video), so that what they take
  // at the start is the world as the others left it (a path's followers
  // placed, a conveyor's belt built), not as the file put it.
  for (const auto& descriptor : registry_.module_descriptors())
    if (descriptor->every_world && find_module(descriptor->info.name) == nullptr)
      InstallModule(descriptor->info.name, descriptor->order, descriptor->phases,
                    descriptor->make(this, nullptr));
  for (const bool observers : {false, true})
    for (const ModuleEntry& e : modules_) {
      if ((e.phases == PhaseBit(Phase::kRecord)) != observers) continue;
      stage("module " + e.name);
      e.instance->Start(this);
    }
  device_services_ = {dynamic_cast<const SensorValueAccess*>(find_module("light")),
                      dynamic_cast<const SensorValueAccess*>(find_module("ground_sensor")),
                      dynamic_cast<const LedAccess*>(find_module("blobs")),
                      dynamic_cast<const IrAccess*>(find_module("ir_messaging"))};
  if (settings_.run_script_memory_limit < 0)
    run_script_memory_.set_limit(
        static_cast<uint64_t>(std::max(WorldSettings::kDefaultRunScriptMemory,
                                       WorldSettings::kRunScriptMemoryPerRobot * robot_count())));
}

void World::Start() {
  if (started_) return;
  if (start_failed_) throw Error("the world failed to start and cannot be started again");
  // Each stage below takes memory in proportion to the robots; the loader's
  // and the Lua states' forecasts see only their own items. A stage that
  // took the process past what it may hold (--max-memory, a cgroup's limit)
  // stops the start there, with a message, before the next takes more.
  std::string last_stage = "loading the world";
  const auto stage = [&](const std::string& next) {
    CheckStop();
    if (std::string why = NoRoomLeft(robot_count(), last_stage, settings_.max_memory); !why.empty())
      throw Error(why);
    last_stage = "starting " + next;
    StartStage(next);
  };
  // A stage that throws (out of memory, a module's error) may leave its
  // part half built: the state hash a failed run still prints, and the
  // world's end, then leave the physics and modules alone.
  try {
    StartParts(stage);
  } catch (...) {
    start_failed_ = true;
    failed_ = true;
    throw;
  }
  // (A Lua world finds a script at its first robot; one of native or Python
  // controllers looks at every slot once.)
  bool any_script = settings_.main_script != nullptr;
  for (uint32_t s = 0; s < scene_.slot_count() && !any_script; ++s)
    any_script = scene_.script_at(s) != nullptr;
  stage(any_script ? "scripts (Lua states, sysCall_init)" : "scripts (none)");
  scripts_ = MakeScriptHost(this);
  started_ = true;
  try {
    scripts_->Start();
    // Native controllers' init, after the scripts' sysCall_init.
    if (controllers_) {
      stage("native controllers' init");
      controllers_->Init(0);
    }
    MarkAllPending();  // sysCall_init may have left anything anywhere
    FlushRobotBuffers();
    stage("");
  } catch (...) {
    failed_ = true;
    FlushBuffersAfterError();  // the other robots' sysCall_init prints
    throw;
  }
}

void World::Step() {
  if (!started_) Start();
  if (failed_) throw Error("the world stopped after an error and cannot be stepped again");
  if (stopped_) throw Error("the world was stopped and cannot be stepped again");
  try {
    // 0. messages and signals sent in the last step become visible.
    {
      PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kControl)]);
      messaging_.Deliver(&scene_, line_of_sight_, *scheduler_);
    }
    if (scripts_->has_main_script()) {
      // 1-4. the world's own main script runs the phases (sim.handleSensing(), ...).
      dynamics_handled_ = false;
      scripts_->RunMainScript();
      // Copies and removals it queued after its last sim.handleActuation().
      ApplyModelEdits();
      if (!dynamics_handled_)
        throw Error("main: " + settings_.main_script->path +
                    ": sysCall_step must call sim.handleDynamics() once per step");
    } else {
      // 1. sense: sensors read the state left by the last physics step.
      {
        PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kSense)]);
        Sense();
      }
      // 2. control: scripts, one robot per task, hierarchy order within a robot.
      {
        PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kControl)]);
        Control();
      }
      // 3. actuate: deferred writes, joint targets, calculation modules (IK).
      {
        PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kActuate)]);
        Actuate();
      }
      // 4. physics: the dynamics backend advances the simulated bodies.
      {
        PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kPhysics)]);
        Physics();
      }
    }
    // What a main script printed and recorded after its last pass belongs
    // to this step's outputs, not the next one's.
    if (scripts_->has_main_script()) FlushSceneBuffers();
    // 5. record: observers append to their streams.
    {
      PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kRecord)]);
      Record();
    }
  } catch (...) {
    failed_ = true;
    if (scripts_->has_main_script()) FlushBuffersAfterError();  // the main script's prints
    throw;
  }
}

void World::Sense() {
  RunModules(Phase::kSense);  // proximity, plugin sensors, ...
  RunPhaseCallbacks(Phase::kSense, PhaseEdge::kEnd);
}

void World::HandleSensing() {
  PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kSense)]);
  Sense();
}
void World::HandleChildScripts(ScriptPass pass) {
  PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kControl)]);
  // What the main script printed so far comes first.
  DrainLog(scene_runtime_, scene_script_memory_);
  Control(pass);
}
void World::HandleActuation() {
  PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kActuate)]);
  Actuate();
}
void World::HandleDynamics() {
  if (dynamics_handled_) throw Error("sim.handleDynamics() may run only once per step");
  dynamics_handled_ = true;
  PhaseTimer t(&phase_times_[static_cast<size_t>(Phase::kPhysics)]);
  Physics();
}

void World::Control(ScriptPass pass) {
  RunPhaseCallbacks(Phase::kControl, PhaseEdge::kStart);
  const auto& instances = scene_.instances();
  // Robots sharing a Lua state (robots_per_lua_state: n, robots r / n) run
  // on one thread: the range is split between groups only.
  const int64_t count = static_cast<int64_t>(instances.size());
  const int64_t n = std::max(1, settings_.robots_per_lua_state);
  scheduler_->ParallelFor(0, (count + n - 1) / n, std::max<int64_t>(1, kRobotGrain / n),
                          [&](int64_t first_group, int64_t end_group) {
                            const int64_t begin = first_group * n;
                            const int64_t end = std::min(count, end_group * n);
                            for (int64_t r = begin; r < end; ++r) {
                              if (!instances[r].alive) continue;
                              try {
                                scripts_->RunInstance(static_cast<int>(r), pass);
                                // A native controller, after the robot's scripts.
                                if (controllers_ && pass != ScriptPass::kSensing)
                                  controllers_->Step(static_cast<int>(r));
                              } catch (const std::exception& e) {
                                runtimes_[r].error = e.what();
                              }
                              pending_[r] |= PendingBits(runtimes_[r]);
                              messaging_.NoteWrites(static_cast<int>(r));
                            }
                          });
  try {
    scripts_->RunSceneScripts(pass);
  } catch (const std::exception& e) {
    scene_runtime_.error = e.what();
  }
  // Signals written in this pass: the robots see them from the next step
  // (they have run), a main script as soon as sim.handleChildScripts returns.
  messaging_.ApplySignalWrites();
  FlushRobotBuffers();
  RunPhaseCallbacks(Phase::kControl, PhaseEdge::kEnd);
}

uint8_t World::PendingBits(const RobotRuntime& rt) {
  uint8_t bits = 0;
  if (!rt.log.empty() || !rt.metrics.empty() || !rt.error.empty() || !rt.disabled.empty())
    bits |= kPendingOutput;
  if (!rt.deferred.empty()) bits |= kPendingDeferred;
  if (!rt.model_edits.empty()) bits |= kPendingModelEdits;
  return bits;
}

void World::MarkAllPending() {
  pending_.assign(runtimes_.size(), 0xff);
  messaging_.MarkAllPending();
}

namespace {
// Moves a robot's samples into the World's `out` and frees the robot's
// buffer, as its account is released (sim.recordMetric charges the
// buffer's capacity). The first buffer becomes the World's as it is.
void TakeSamples(std::vector<MetricSample>* samples, std::vector<MetricSample>* out) {
  if (out->empty()) {
    out->swap(*samples);
  } else {
    for (MetricSample& m : *samples) out->push_back(std::move(m));
  }
  std::vector<MetricSample>().swap(*samples);
}
}  // namespace

void World::FlushRobotBuffers() {
  // Logs and metrics in robot order, then the scene's; the lowest robot's
  // error wins, so the report does not depend on the thread count.
  std::string first_error;
  auto flush = [&](RobotRuntime& rt, ScriptMemory& memory) {
    DrainLog(rt, memory);
    TakeSamples(&rt.metrics, &metrics_);
    memory.Release(std::exchange(rt.metric_bytes, 0));
    if (!rt.error.empty() && first_error.empty()) first_error = rt.error;
    rt.error.clear();
    for (std::string& why : rt.disabled) disabled_scripts_.push_back(std::move(why));
    rt.disabled.clear();
  };
  for (size_t r = 0; r < runtimes_.size(); ++r) {
    if (!(pending_[r] & kPendingOutput)) continue;
    flush(runtimes_[r], robot_script_memory_[r]);
    pending_[r] &= ~kPendingOutput;
  }
  flush(scene_runtime_, scene_script_memory_);
  if (!first_error.empty()) throw Error(first_error);
}

void World::FlushSceneBuffers() {
  DrainLog(scene_runtime_, scene_script_memory_);
  TakeSamples(&scene_runtime_.metrics, &metrics_);
  scene_script_memory_.Release(std::exchange(scene_runtime_.metric_bytes, 0));
}

void World::DrainLog(RobotRuntime& rt, ScriptMemory& memory) {
  rt.log.Drain(log_sink_);
  memory.Release(std::exchange(rt.log_bytes, 0));
}

void World::FlushBuffersAfterError() noexcept {
  MarkAllPending();
  try {
    FlushRobotBuffers();
  } catch (...) {
    // A buffered error: the one in flight came first or from a lower robot.
  }
}

void World::Actuate() {
  // Robots copied and removed by the scripts (world_model_edits.cc).
  ApplyModelEdits();
  // Writes to other robots' objects, in handle order (stable for equal handles).
  std::vector<DeferredWrite> writes;
  for (size_t r = 0; r < runtimes_.size(); ++r) {
    if (!(pending_[r] & kPendingDeferred)) continue;
    RobotRuntime& rt = runtimes_[r];
    writes.insert(writes.end(), rt.deferred.begin(), rt.deferred.end());
    robot_script_memory_[r].Release(rt.deferred.size() * sizeof(DeferredWrite));
    rt.deferred.clear();
    pending_[r] &= ~kPendingDeferred;
  }
  writes.insert(writes.end(), scene_runtime_.deferred.begin(), scene_runtime_.deferred.end());
  scene_script_memory_.Release(scene_runtime_.deferred.size() * sizeof(DeferredWrite));
  scene_runtime_.deferred.clear();
  std::stable_sort(
      writes.begin(), writes.end(),
      [](const DeferredWrite& a, const DeferredWrite& b) { return a.object < b.object; });
  for (const DeferredWrite& w : writes) {
    if (!scene_.IsValid(w.object)) continue;  // removed meanwhile
    if (w.kind == DeferredWrite::Kind::kObjectPose) {
      scene_.SetWorldPose(w.object, w.pose);
      continue;
    }
    if (w.kind == DeferredWrite::Kind::kShapeDynamic) {
      scene_.SetShapeDynamic(w.object, w.value != 0);
      continue;
    }
    if (w.kind == DeferredWrite::Kind::kSizeFactor) {
      scene_.ScaleSubtree(w.object, w.value / scene_.size_factor(w.object));
      continue;
    }
    JointData& j = scene_.mutable_joint(w.object);
    if (w.kind == DeferredWrite::Kind::kJointPosition) {
      if (!j.simulated && !j.depends()) j.JumpTo(w.value);  // checked when the script called
      continue;
    }
    if (w.kind == DeferredWrite::Kind::kJointTargetVelocity)
      j.target_velocity = w.value;
    else
      j.target_position = w.value;
  }
  // Calculation objects (IK groups, ...) set joint positions and targets.
  RunModules(Phase::kActuate);
  // Joints move kinematically toward their targets over the control step:
  // velocity mode at the target velocity, position mode at up to max_velocity.
  const double dt = settings_.time_step;
  // One pass over the joints. Motors with actuation noise (scene.h:
  // JointSettings::velocity_noise) draw this step's speed first, from the
  // stream of (seed, joint slot, step): the backends drive it too.
  const std::span<JointData> joints = scene_.joints();
  for (size_t r = 0; r < joints.size(); ++r) {
    JointData& j = joints[r];
    if (j.mode() == JointMode::kVelocity && j.settings->drive_noisy()) {
      const JointSettings& s = *j.settings;
      Rng rng =
          NoiseStream(settings_.seed, scene_.joint_owners()[r], step_count_, NoisePurpose::kWheels);
      double v = j.target_velocity * (1 - s.slip);
      if (s.velocity_noise_factor > 0) v *= 1 + rng.Normal(0, s.velocity_noise_factor);
      v = Perturb(s.velocity_noise, v, rng);
      j.drive_velocity = Fails(s.velocity_noise, rng) ? 0.0 : v;
    }
    if (j.simulated || j.depends()) continue;  // the dynamics backend, or its master, moves it
    switch (j.mode()) {
      // Stopped at the joint's limits, as ODE's stops hold them.
      case JointMode::kVelocity: {
        const double lo = std::min(j.position, j.settings->min_position);
        const double hi = std::max(j.position, j.settings->max_position);
        j.velocity = j.DriveVelocity();
        const double next = j.position + j.velocity * dt;
        if (next < lo || next > hi) j.velocity = (std::clamp(next, lo, hi) - j.position) / dt;
        j.position = std::clamp(next, lo, hi);
        break;
      }
      case JointMode::kPosition: {
        const double error =
            std::clamp(j.target_position, std::min(j.position, j.settings->min_position),
                       std::max(j.position, j.settings->max_position)) -
            j.position;
        const double max_step = j.settings->max_velocity * dt;
        const double step = std::clamp(error, -max_step, max_step);
        j.velocity = step / dt;
        j.position += step;
        break;
      }
      case JointMode::kPassive:
      case JointMode::kForce: break;
    }
  }
  // Dependent joints follow their masters (simulated ones: as position targets).
  dependent_joints_.Apply(&scene_, true);
}

void World::Physics() {
  dynamics_->Step(&scene_, settings_.time_step / settings_.physics_substeps,
                  settings_.physics_substeps);
  // Joints that follow a master the dynamics moved, before their children's poses.
  dependent_joints_.Apply(&scene_, false);
  // Objects carried by the simulated bodies follow them.
  UpdateWorldPoses(&scene_, *scheduler_);
  ++step_count_;
  time_ = static_cast<double>(step_count_) * settings_.time_step;
  // NaNs and infinities out of physics are a user-visible error, not garbage
  // in the outputs and the state hash: body poses and velocities, joints.
  const auto non_finite = [&](uint32_t slot, const char* what) {
    return Error("physics produced a non-finite " + std::string(what) + " for '" +
                 scene_.PathOf(scene_.IdAt(slot)) + "' at step " + std::to_string(step_count_) +
                 " (check masses, sizes and joint targets)");
  };
  const auto out_of_bounds = [&](uint32_t slot, const Vec3& p) {
    std::ostringstream m;
    m << std::setprecision(10) << "physics moved '" << scene_.PathOf(scene_.IdAt(slot)) << "' to ("
      << p.x << ", " << p.y << ", " << p.z << ") m at step " << step_count_
      << ", beyond the 1e6 m a world may use: the simulation blew up (check masses, sizes and "
         "joint targets; "
         "try a smaller time_step or more physics_substeps";
    if (settings_.physics == "ode") m << ", or ode: {solver: world}";
    m << ")";
    return Error(m.str());
  };
  for (uint32_t row = 0; row < scene_.shapes().size(); ++row) {
    const uint32_t slot = scene_.shape_owners()[row];
    if (!scene_.shapes()[row].dynamic) continue;
    const Pose& X_WB = scene_.world_pose_at(slot);
    if (!IsFinite(X_WB)) throw non_finite(slot, "pose");
    if (!IsFinite(scene_.linear_velocity_at(slot)) || !IsFinite(scene_.angular_velocity_at(slot)))
      throw non_finite(slot, "velocity");
    // A body past the world's bounds: the simulation blew up (a finite
    // 1e96 m is as much garbage as a NaN, only later).
    if (!WithinWorld(X_WB.p)) throw out_of_bounds(slot, X_WB.p);
  }
  const auto joints = scene_.joints();
  for (uint32_t row = 0; row < joints.size(); ++row)
    if (!std::isfinite(joints[row].position) || !std::isfinite(joints[row].velocity))
      throw non_finite(scene_.joint_owners()[row], "joint position or velocity");
  RunModules(Phase::kPhysics);  // after the engine: mills, collision, ...
  RunPhaseCallbacks(Phase::kPhysics, PhaseEdge::kEnd);
}

void World::Record() {
  RunModules(Phase::kRecord);  // swarm metrics, paint, ...
  if (CallbacksAt(Phase::kRecord, PhaseEdge::kEnd).empty()) return;
  // Plugins' record-phase callbacks, then their rows in robot order (the
  // swarm-level ones first), whatever the thread count.
  recording_ = true;
  try {
    RunPhaseCallbacks(Phase::kRecord, PhaseEdge::kEnd);
  } catch (...) {
    recording_ = false;
    plugin_metrics_.clear();
    throw;
  }
  recording_ = false;
  std::stable_sort(
      plugin_metrics_.begin(), plugin_metrics_.end(),
      [](const MetricSample& a, const MetricSample& b) { return a.instance < b.instance; });
  for (MetricSample& m : plugin_metrics_) metrics_.push_back(std::move(m));
  plugin_metrics_.clear();
}

void World::SetNativeController(int robot, const PluginControllerType* type,
                                bool in_place_of_scripts) {
  if (started_) throw Error("native controllers are attached before the world starts");
  if (!controllers_) controllers_ = std::make_unique<PluginControllers>(this);
  controllers_->Reserve(runtimes_.capacity());  // as many as ReserveRobots said
  controllers_->Assign(robot, type, in_place_of_scripts);
}

void World::Stop() {
  if (stopped_ || !started_) return;
  stopped_ = true;
  // Native controllers' cleanup (it cannot fail), before the scripts'.
  if (controllers_) controllers_->CleanupAll();
  if (scripts_) {
    try {
      scripts_->Stop();
    } catch (...) {
      FlushBuffersAfterError();  // every robot's cleanup prints, then the error
      throw;
    }
    MarkAllPending();
    FlushRobotBuffers();  // cleanup's prints and errors
  }
}

uint64_t World::StateHash() const {
  StateHasher h;
  h.AddValue(step_count_);
  h.AddValue(time_);
  for (uint32_t s = 0; s < scene_.slot_count(); ++s) {
    if (!scene_.alive_at(s)) continue;
    h.AddValue(s);
    h.AddValue(scene_.world_pose_at(s));
    h.AddValue(scene_.linear_velocity_at(s));
    h.AddValue(scene_.angular_velocity_at(s));
  }
  // Each type's changing state, types in listing order (object_type.h).
  for (const ObjectType t : scene_.listing_order())
    if (const auto hash_rows = scene_.type_descriptor(t).hash_rows) hash_rows(scene_, t, &h);
  // Robots removed at run time are not hashed.
  for (size_t r = 0; r < runtimes_.size(); ++r)
    if (scene_.instances()[r].alive) h.Add(runtimes_[r].rng.state(), 4 * sizeof(uint64_t));
  h.Add(scene_runtime_.rng.state(), 4 * sizeof(uint64_t));
  // Model parameters set after load (Python's set_param), only when there are.
  if (!loaded_parameters_.empty()) HashWrittenParameters(&h);
  // What scripts left for the next step: signals and mail not yet delivered
  // (Messaging), custom data blocks.
  messaging_.HashState(&h);
  for (uint32_t s = 0; s < scene_.slot_count(); ++s)
    if (scene_.alive_at(s)) scene_.HashCustomData(s, &h);
  if (start_failed_) return h.Digest();  // physics and modules half built
  if (dynamics_) dynamics_->HashState(&h);
  for (const ModuleEntry& e : modules_) e.instance->HashState(&h);
  return h.Digest();
}

}  // namespace swarmsim
