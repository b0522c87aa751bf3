// The module registry: every calculation module (dynamics engines, sensors,
// later plugins) registers here by name with a version and a one-line
// description, so the program can list what it has (`swarmsim modules`).
// The registry is an ordinary object (no globals): the program builds one
// and hands it to each World.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "framework/dynamics_backend.h"
#include "framework/module.h"
#include "framework/plugin_api.h"

namespace swarmsim {

class DynamicsBackend;
class ObjectReader;
class Scene;
struct ObjectKey;
struct ObjectTypeDescriptor;
struct PluginControllerType;
struct VisionFilterDescriptor;
struct WorldSectionDescriptor;
struct EnvironmentFormatDescriptor;
struct ViewRecorderDescriptor;
struct ModelSectionDescriptor;

// A script command registered by a plugin (framework/plugin_api.h): sim.<name>.
struct ScriptCommand {
  std::string name;
  std::string description;
  SwarmsimCommand function = nullptr;
  void* user_data = nullptr;
};

// A per-phase callback registered by a plugin (framework/plugin_api.h).
struct PhaseCallback {
  std::string name;  // "plugin:phase", for messages
  // The plugin's SwarmsimPhase as a point of the step: after_sense is
  // (kSense, kEnd), before_control (kControl, kStart), ...
  Phase phase = Phase::kSense;
  PhaseEdge edge = PhaseEdge::kEnd;
  bool per_robot = false;
  SwarmsimPhaseCallback function = nullptr;
  void* user_data = nullptr;
};

// A sensor type registered by a plugin (framework/plugin_api.h). Its objects
// are of type plugin_sensor (framework/types/plugin_sensor_type.cc).
struct PluginSensorType {
  std::string name;  // as models write it: {type: plugin_sensor, sensor: NAME}
  std::string description;
  SwarmsimSensorFunction function = nullptr;
  void* user_data = nullptr;
  int max_values = SWARMSIM_SENSOR_MAX_VALUES;  // numbers one reading holds at most
};

// A backend's own mapping in the world's `simulation:` section, under the
// backend's name (`simulation: {physics: ode, ode: {solver: world}}`): its
// keys with defaults and docs (worlds/README.md lists them) and a reader.
struct DynamicsSection {
  std::span<const ObjectKey> keys;
  // Reads the mapping (errors name file:line:column through the reader).
  std::function<std::shared_ptr<const DynamicsOptions>(const ObjectReader& reader)> read;
};

class ModuleRegistry {
 public:
  using DynamicsFactory = std::function<std::unique_ptr<DynamicsBackend>()>;
  using CalculationFactory = std::function<std::unique_ptr<Module>()>;
  // The engine alone stepping a world's bodies `steps` times (swarmsim
  // bench's "<physics>-only" row): wall seconds.
  using BareLoop = std::function<double(const Scene& scene, double time_step, int substeps,
                                        int steps, double gravity)>;

  // Dynamics backends: kind "dynamics", chosen by a world's `physics:`.
  void RegisterDynamics(ModuleInfo info, DynamicsCapabilities capabilities, DynamicsFactory factory,
                        BareLoop bare_loop = {});
  // The settings section of the registered backend `name` (throws Error if
  // there is no such backend).
  void RegisterDynamicsSection(const std::string& name, DynamicsSection section);
  // Null if backend `name` has none (or is not registered).
  const DynamicsSection* FindDynamicsSection(const std::string& name) const;
  // Modules (framework/module.h): every other kind. Throws swarmsim::Error
  // if the name is taken or the descriptor has no `make`.
  void RegisterModule(ModuleDescriptor module);
  // Null if no module has that name.
  const ModuleDescriptor* FindModule(std::string_view name) const;
  // Every module of `kind`, in registration order.
  std::vector<const ModuleDescriptor*> ModulesOfKind(std::string_view kind) const;
  const std::vector<std::shared_ptr<const ModuleDescriptor>>& module_descriptors() const {
    return module_descriptors_;
  }
  // A calculation module (IK groups, ...): kind "calculation", actuate
  // phase, order 100, made on request (World::module).
  void RegisterCalculation(ModuleInfo info, CalculationFactory factory);
  // Script commands (plugins): kind "command". Throws swarmsim::Error if the
  // name is not a Lua identifier or is already a command.
  void RegisterScriptCommand(ModuleInfo info, ScriptCommand command);
  // Null if no command has that name.
  const ScriptCommand* FindScriptCommand(std::string_view name) const;
  // Phase callbacks (plugins): kind "callback".
  void RegisterPhaseCallback(ModuleInfo info, PhaseCallback callback);
  const std::vector<PhaseCallback>& phase_callbacks() const { return phase_callbacks_; }
  // Plugin sensor types: kind "sensor". Throws swarmsim::Error if the name is taken.
  void RegisterPluginSensor(ModuleInfo info, PluginSensorType type);
  // Null if no sensor type has that name.
  const PluginSensorType* FindPluginSensor(std::string_view name) const;
  const std::vector<PluginSensorType>& plugin_sensors() const { return plugin_sensors_; }
  // Object types of modules and plugins (framework/object_type.h): kind
  // "object type". Every World's Scene registers them after the built-in
  // types, in this order. Throws swarmsim::Error if the name is taken
  // (built-in names included).
  void RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor> type);
  std::span<const ObjectTypeDescriptor* const> object_types() const { return object_types_; }
  // Vision-sensor filter elements (framework/vision_filter.h): kind "vision
  // filter". The built-in ones (modules/rendering/filters) and plugins'
  // (add_vision_filter) alike. Throws swarmsim::Error if the name is taken
  // or the descriptor has neither `make` nor a plugin function.
  void RegisterVisionFilter(std::shared_ptr<const VisionFilterDescriptor> filter);
  // Null if no element has that name.
  const VisionFilterDescriptor* FindVisionFilter(std::string_view name) const;
  const std::vector<std::shared_ptr<const VisionFilterDescriptor>>& vision_filters() const {
    return vision_filters_;
  }
  // World-file sections (framework/world_section.h): a top-level key a
  // module reads itself. Not listed by `swarmsim modules` (its module is).
  // Throws swarmsim::Error if the key is taken.
  void RegisterWorldSection(std::shared_ptr<const WorldSectionDescriptor> section);
  // In registration order, the order the loader reads them in.
  const std::vector<std::shared_ptr<const WorldSectionDescriptor>>& world_sections() const {
    return world_sections_;
  }
  // Model-file sections (framework/model_section.h): a model file's key a
  // module reads itself (`ik_groups`). Throws swarmsim::Error if the key is
  // taken or the descriptor lacks `read` or `apply`.
  void RegisterModelSection(std::shared_ptr<const ModelSectionDescriptor> section);
  // In registration order, the order the loader reads and applies them in.
  const std::vector<std::shared_ptr<const ModelSectionDescriptor>>& model_sections() const {
    return model_sections_;
  }
  // Map formats of the world's `environment:` key (framework/world_section.h).
  // Throws swarmsim::Error if the key is taken.
  void RegisterEnvironmentFormat(std::shared_ptr<const EnvironmentFormatDescriptor> format);
  const std::vector<std::shared_ptr<const EnvironmentFormatDescriptor>>& environment_formats()
      const {
    return environment_formats_;
  }
  // The recorder of snapshots and videos (framework/view_recorder.h): one
  // per program (modules/rendering/video). Throws swarmsim::Error if one is
  // registered already or the descriptor has no `add`.
  void RegisterViewRecorder(std::shared_ptr<const ViewRecorderDescriptor> recorder);
  // Null when none is registered.
  const ViewRecorderDescriptor* view_recorder() const { return view_recorder_.get(); }
  // Native controllers (plugins, framework/plugin_controllers.h): kind
  // "controller". Throws swarmsim::Error if the name is taken.
  void RegisterController(ModuleInfo info, PluginControllerType controller);
  // Null if no controller has that name.
  const PluginControllerType* FindController(std::string_view name) const;
  std::vector<std::string> ControllerNames() const;
  // Plugins loaded into this registry, by canonical path (LoadPlugin records them).
  void AddPluginPath(std::string path) { plugin_paths_.push_back(std::move(path)); }
  bool HasPlugin(std::string_view path) const;

  // Throw swarmsim::Error listing what is available when `name` is unknown.
  std::unique_ptr<DynamicsBackend> MakeDynamics(const std::string& name) const;
  // Null if the dynamics backend has no bare loop.
  const BareLoop* FindBareLoop(const std::string& physics) const;
  bool HasDynamics(const std::string& name) const;
  // What the backend named `name` declared. Throws swarmsim::Error listing
  // the backends when there is none of that name.
  const DynamicsCapabilities& dynamics_capabilities(const std::string& name) const;
  std::vector<std::string> DynamicsNames() const;

  const std::vector<ModuleInfo>& modules() const { return modules_; }

 private:
  std::vector<ModuleInfo> modules_;
  struct Dynamics {
    std::string name;
    DynamicsCapabilities capabilities;
    DynamicsFactory factory;
    BareLoop bare_loop;
    std::shared_ptr<const DynamicsSection> section;  // null: none
  };
  std::vector<Dynamics> dynamics_;
  // Shared: a world's copy of the registry (plus its plugins) keeps them.
  std::vector<std::shared_ptr<const ModuleDescriptor>> module_descriptors_;
  std::vector<std::shared_ptr<const ScriptCommand>>
      commands_;  // stable addresses (Lua keeps pointers)
  std::vector<PhaseCallback> phase_callbacks_;
  std::vector<PluginSensorType> plugin_sensors_;
  std::vector<std::string> plugin_paths_;
  std::vector<std::shared_ptr<const ObjectTypeDescriptor>> owned_object_types_;
  std::vector<const ObjectTypeDescriptor*> object_types_;
  std::vector<std::shared_ptr<const VisionFilterDescriptor>> vision_filters_;
  std::vector<std::shared_ptr<const WorldSectionDescriptor>> world_sections_;
  std::vector<std::shared_ptr<const EnvironmentFormatDescriptor>> environment_formats_;
  std::shared_ptr<const ViewRecorderDescriptor> view_recorder_;
  std::vector<std::shared_ptr<const ModelSectionDescriptor>> model_sections_;
  // Shared, stable addresses: a world's robots point at them.
  std::vector<std::shared_ptr<const PluginControllerType>> controllers_;
};

}  // namespace swarmsim
