#include "framework/plugin_loader.h"

#include <cstdio>
#include <filesystem>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/plugin_api.h"
#include "framework/plugin_controllers.h"
#include "framework/plugin_object_type.h"
#include "framework/registry.h"
#include "framework/shared_library.h"
#include "framework/vision_filter.h"

namespace swarmsim {
namespace {

// What a plugin registers, gathered before it goes into the registry.
struct Registration {
  ModuleInfo info;
  std::vector<ScriptCommand> commands;
  std::vector<PhaseCallback> callbacks;
  std::vector<PluginSensorType> sensors;
  std::vector<std::shared_ptr<const ObjectTypeDescriptor>> object_types;
  std::vector<std::shared_ptr<const VisionFilterDescriptor>> vision_filters;
  std::vector<PluginControllerType> controllers;
  std::string error;
};

const char* PhaseName(int phase) {
  switch (phase) {
    case kSwarmsimAfterSense: return "after_sense";
    case kSwarmsimBeforeControl: return "before_control";
    case kSwarmsimAfterControl: return "after_control";
    case kSwarmsimAfterPhysics: return "after_physics";
    case kSwarmsimRecord: return "record";
  }
  return "?";
}

// The plugin ABI's points of a step as (phase, edge) of the step's phases.
Phase PhaseOf(int phase) {
  switch (phase) {
    case kSwarmsimAfterSense: return Phase::kSense;
    case kSwarmsimBeforeControl:
    case kSwarmsimAfterControl: return Phase::kControl;
    case kSwarmsimAfterPhysics: return Phase::kPhysics;
    default: return Phase::kRecord;
  }
}
PhaseEdge EdgeOf(int phase) {
  return phase == kSwarmsimBeforeControl ? PhaseEdge::kStart : PhaseEdge::kEnd;
}

int AddPhaseCallback(void* impl, int phase, int per_robot, SwarmsimPhaseCallback callback,
                     void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  if (phase < 0 || phase >= kSwarmsimPhaseCount || callback == nullptr) {
    r->error = "add_phase_callback needs a phase (SwarmsimPhase) and a function";
    return -1;
  }
  r->callbacks.push_back(
      {PhaseName(phase), PhaseOf(phase), EdgeOf(phase), per_robot != 0, callback, user_data});
  return 0;
}

int AddCommand(void* impl, const char* name, const char* description, SwarmsimCommand command,
               void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  if (name == nullptr || command == nullptr) {
    r->error = "add_command needs a name and a function";
    return -1;
  }
  r->commands.push_back({name, description != nullptr ? description : "", command, user_data});
  return 0;
}

int AddSensorTypeOfSize(void* impl, const char* name, const char* description, int max_values,
                        SwarmsimSensorFunction sense, void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  if (name == nullptr || name[0] == 0 || sense == nullptr || max_values < 1) {
    r->error = "add_sensor_type needs a name, a function and a reading of at least one number";
    return -1;
  }
  r->sensors.push_back(
      {name, description != nullptr ? description : "", sense, user_data, max_values});
  return 0;
}

int AddSensorType(void* impl, const char* name, const char* description,
                  SwarmsimSensorFunction sense, void* user_data) {
  return AddSensorTypeOfSize(impl, name, description, SWARMSIM_SENSOR_MAX_VALUES, sense, user_data);
}

int AddObjectType(void* impl, const char* name, const char* description,
                  const SwarmsimObjectKey* keys, int key_count) {
  auto* r = static_cast<Registration*>(impl);
  if (name == nullptr || name[0] == 0 || key_count < 0 || (key_count > 0 && keys == nullptr)) {
    r->error = "add_object_type needs a name and its keys";
    return -1;
  }
  try {
    r->object_types.push_back(
        MakePluginObjectType(name, description != nullptr ? description : "",
                             std::vector<SwarmsimObjectKey>(keys, keys + key_count)));
  } catch (const Error& e) {
    r->error = e.what();
    return -1;
  }
  return 0;
}

int AddVisionFilter(void* impl, const char* name, const char* description, int input_kinds,
                    int output_kind, const SwarmsimObjectKey* keys, int key_count, int max_values,
                    SwarmsimFilterFunction filter, void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  constexpr int kAllKinds = kSwarmsimColourImage | kSwarmsimGreyImage | kSwarmsimMask |
                            kSwarmsimDepthImage | kSwarmsimValues;
  const bool one_kind = output_kind == 0 || (output_kind & (output_kind - 1)) == 0;
  if (name == nullptr || name[0] == 0 || filter == nullptr || (input_kinds & kAllKinds) == 0 ||
      (input_kinds & ~kAllKinds) != 0 || (output_kind & ~kAllKinds) != 0 || !one_kind ||
      key_count < 0 || (key_count > 0 && keys == nullptr) || max_values < 0) {
    r->error =
        "add_vision_filter needs a name, a function, input kinds and at most one output kind "
        "(SwarmsimImageKind)";
    return -1;
  }
  auto d = std::make_shared<VisionFilterDescriptor>();
  d->name = name;
  d->description = description != nullptr ? description : "";
  d->input = static_cast<uint32_t>(input_kinds);
  d->output = static_cast<uint32_t>(output_kind);
  for (int k = 0; k < key_count; ++k) {
    const SwarmsimObjectKey& key = keys[k];
    if (key.name == nullptr || key.name[0] == 0 || key.name == std::string("type") ||
        !(key.min <= key.default_value && key.default_value <= key.max)) {
      r->error = "vision filter '" + d->name +
                 "': a key needs a name other than 'type' and a default within its range";
      return -1;
    }
    char default_text[32];
    std::snprintf(default_text, sizeof default_text, "%g", key.default_value);
    d->keys.push_back({key.name, default_text, key.doc != nullptr ? key.doc : "", key.default_value,
                       key.min, key.max});
  }
  d->plugin_function = filter;
  d->plugin_user_data = user_data;
  d->plugin_max_values = max_values;
  r->vision_filters.push_back(std::move(d));
  return 0;
}

int AddController(void* impl, const char* name, const char* description,
                  SwarmsimControllerInit init, SwarmsimControllerStep step,
                  SwarmsimControllerCleanup cleanup, void* user_data) {
  auto* r = static_cast<Registration*>(impl);
  if (name == nullptr || name[0] == 0 || step == nullptr) {
    r->error = "add_controller needs a name and a step function";
    return -1;
  }
  for (const PluginControllerType& c : r->controllers)
    if (c.name == name) {
      r->error = "add_controller: the controller '" + c.name + "' is registered twice";
      return -1;
    }
  r->controllers.push_back(
      {name, description != nullptr ? description : "", "", init, step, cleanup, user_data});
  return 0;
}

void SetInfo(void* impl, const char* name, const char* version, const char* description) {
  auto* r = static_cast<Registration*>(impl);
  if (name != nullptr) r->info.name = name;
  if (version != nullptr) r->info.version = version;
  if (description != nullptr) r->info.description = description;
}

}  // namespace

void LoadPlugin(const std::string& path, ModuleRegistry* registry) {
  // A bare name would be searched in the system's library path: say "./x.so".
  const std::string name = path.find('/') == std::string::npos ? "./" + path : path;
  std::string why;
  void* library = OpenSharedLibrary(name, &why);
  if (library == nullptr) throw Error("cannot load plugin '" + path + "': " + why);
  using VersionFunction = int (*)();
  using RegisterFunction = int (*)(const SwarmsimRegistrar*);
  auto version =
      reinterpret_cast<VersionFunction>(FindSymbol(library, "swarmsim_plugin_abi_version"));
  auto do_register =
      reinterpret_cast<RegisterFunction>(FindSymbol(library, "swarmsim_plugin_register"));
  if (version == nullptr || do_register == nullptr)
    throw Error("plugin '" + path + "' is not a swarmsim plugin: it does not export " +
                (version == nullptr ? "swarmsim_plugin_abi_version" : "swarmsim_plugin_register") +
                " (see framework/plugin_api.h)");
  // Versions from the oldest up only added at the end of the structs: an
  // older plugin sees the prefix it was built for.
  if (const int v = version(); v < SWARMSIM_PLUGIN_ABI_OLDEST || v > SWARMSIM_PLUGIN_ABI_VERSION)
    throw Error("plugin '" + path + "' was built for plugin ABI version " + std::to_string(v) +
                ", this swarmsim has version " + std::to_string(SWARMSIM_PLUGIN_ABI_VERSION) +
                " (and loads plugins of versions " + std::to_string(SWARMSIM_PLUGIN_ABI_OLDEST) +
                " to " + std::to_string(SWARMSIM_PLUGIN_ABI_VERSION) +
                "); rebuild it against this framework/plugin_api.h");
  Registration r;
  r.info.name.assign(path);
  r.info.version.assign("unversioned");
  const SwarmsimRegistrar registrar{&r,
                                    AddCommand,
                                    SetInfo,
                                    AddPhaseCallback,
                                    AddSensorType,
                                    AddObjectType,
                                    AddSensorTypeOfSize,
                                    AddVisionFilter,
                                    AddController};
  if (do_register(&registrar) != 0 || !r.error.empty()) {
    std::string message = "plugin '" + path + "' failed to register";
    if (!r.error.empty()) message.append(": ").append(r.error);
    throw Error(message);
  }
  for (ScriptCommand& command : r.commands) {
    ModuleInfo info = r.info;
    info.name = r.info.name + ":" + command.name;
    info.description = command.description;
    try {
      registry->RegisterScriptCommand(info, std::move(command));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
  for (PhaseCallback& callback : r.callbacks) {
    ModuleInfo info = r.info;
    info.name = r.info.name + ":" + callback.name;
    info.description = std::string(callback.per_robot ? "per-robot" : "whole-world") +
                       " callback, " + callback.name;
    callback.name = info.name;
    registry->RegisterPhaseCallback(info, std::move(callback));
  }
  for (PluginSensorType& sensor : r.sensors) {
    ModuleInfo info = r.info;
    info.name = r.info.name + ":" + sensor.name;
    info.description = sensor.description;
    try {
      registry->RegisterPluginSensor(info, std::move(sensor));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
  for (std::shared_ptr<const ObjectTypeDescriptor>& type : r.object_types) {
    try {
      registry->RegisterObjectType(std::move(type));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
  for (std::shared_ptr<const VisionFilterDescriptor>& filter : r.vision_filters) {
    auto named = std::make_shared<VisionFilterDescriptor>(*filter);
    named->version = r.info.version;
    try {
      registry->RegisterVisionFilter(std::move(named));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
  for (PluginControllerType& controller : r.controllers) {
    ModuleInfo info = r.info;
    info.name = r.info.name + ":" + controller.name;
    info.description = controller.description;
    controller.plugin = path;
    try {
      registry->RegisterController(info, std::move(controller));
    } catch (const Error& e) {
      throw Error("plugin '" + path + "': " + e.what());
    }
  }
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(name, ec);
  registry->AddPluginPath(ec ? name : canonical.string());
}

}  // namespace swarmsim
