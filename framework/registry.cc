#include "framework/registry.h"

#include <cctype>

#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/model_section.h"
#include "framework/object_type.h"
#include "framework/view_recorder.h"
#include "framework/vision_filter.h"
#include "framework/world_section.h"

namespace swarmsim {

void ModuleRegistry::RegisterDynamics(ModuleInfo info, DynamicsCapabilities capabilities,
                                      DynamicsFactory factory, BareLoop bare_loop) {
  info.kind = "dynamics";
  dynamics_.push_back({info.name, capabilities, std::move(factory), std::move(bare_loop), nullptr});
  modules_.push_back(std::move(info));
}

void ModuleRegistry::RegisterDynamicsSection(const std::string& name, DynamicsSection section) {
  for (Dynamics& d : dynamics_)
    if (d.name == name) {
      d.section = std::make_shared<const DynamicsSection>(std::move(section));
      return;
    }
  throw Error("no dynamics backend '" + name + "' to give a settings section");
}

const DynamicsSection* ModuleRegistry::FindDynamicsSection(const std::string& name) const {
  for (const Dynamics& d : dynamics_)
    if (d.name == name) return d.section.get();
  return nullptr;
}

void ModuleRegistry::RegisterModule(ModuleDescriptor module) {
  if (module.info.name.empty() || !module.make)
    throw Error("a module needs a name and a way to make it");
  if (FindModule(module.info.name) != nullptr)
    throw Error("module '" + module.info.name + "' is registered twice");
  modules_.push_back(module.info);
  module_descriptors_.push_back(std::make_shared<const ModuleDescriptor>(std::move(module)));
}

const ModuleDescriptor* ModuleRegistry::FindModule(std::string_view name) const {
  for (const auto& m : module_descriptors_)
    if (m->info.name == name) return m.get();
  return nullptr;
}

std::vector<const ModuleDescriptor*> ModuleRegistry::ModulesOfKind(std::string_view kind) const {
  std::vector<const ModuleDescriptor*> out;
  for (const auto& m : module_descriptors_)
    if (m->info.kind == kind) out.push_back(m.get());
  return out;
}

void ModuleRegistry::RegisterCalculation(ModuleInfo info, CalculationFactory factory) {
  info.kind = "calculation";
  RegisterModule({std::move(info), PhaseBit(Phase::kActuate), 100, /*every_world=*/false,
                  [factory = std::move(factory)](World*, const void*) { return factory(); }});
}

void ModuleRegistry::RegisterScriptCommand(ModuleInfo info, ScriptCommand command) {
  const std::string& n = command.name;
  const bool identifier =
      !n.empty() && !std::isdigit(static_cast<unsigned char>(n[0])) &&
      n.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
          std::string::npos;
  if (!identifier) throw Error("script command name '" + n + "' is not a Lua identifier");
  if (FindScriptCommand(n) != nullptr)
    throw Error("script command '" + n + "' is registered twice");
  info.kind = "command";
  modules_.push_back(std::move(info));
  commands_.push_back(std::make_shared<const ScriptCommand>(std::move(command)));
}

const ScriptCommand* ModuleRegistry::FindScriptCommand(std::string_view name) const {
  for (const auto& c : commands_)
    if (c->name == name) return c.get();
  return nullptr;
}

void ModuleRegistry::RegisterPhaseCallback(ModuleInfo info, PhaseCallback callback) {
  if (callback.phase >= Phase::kCount || callback.function == nullptr)
    throw Error("phase callback '" + callback.name + "' has an unknown phase or no function");
  info.kind = "callback";
  modules_.push_back(std::move(info));
  phase_callbacks_.push_back(std::move(callback));
}

void ModuleRegistry::RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor> type) {
  if (!type || type->name == nullptr || *type->name == '\0')
    throw Error("an object type needs a name");
  const std::string name = type->name;
  for (const ObjectTypeDescriptor* t : CoreObjectTypes())
    if (name == t->name) throw Error("object type '" + name + "' is a built-in type");
  // The loader's own shorthand: a registered type of the same name would
  // never be reached (model files would build a ring of sensors instead).
  if (name == "proximity_ring" || name == "ground_array" || name == "light_sensor_ring")
    throw Error("object type '" + name + "' is a world-file type of the loader's");
  for (const ObjectTypeDescriptor* t : object_types_)
    if (name == t->name) throw Error("object type '" + name + "' is registered twice");
  modules_.push_back({"object type", name, "", type->description ? type->description : ""});
  object_types_.push_back(type.get());
  owned_object_types_.push_back(std::move(type));
}

void ModuleRegistry::RegisterVisionFilter(std::shared_ptr<const VisionFilterDescriptor> filter) {
  if (!filter || filter->name.empty()) throw Error("a vision filter element needs a name");
  if (!filter->make && filter->plugin_function == nullptr)
    throw Error("vision filter element '" + filter->name + "' has no way to make it");
  if (FindVisionFilter(filter->name) != nullptr)
    throw Error("vision filter element '" + filter->name + "' is registered twice");
  modules_.push_back({"vision filter", filter->name, filter->version, filter->description});
  vision_filters_.push_back(std::move(filter));
}

void ModuleRegistry::RegisterWorldSection(std::shared_ptr<const WorldSectionDescriptor> section) {
  if (!section || section->key.empty() || !section->read)
    throw Error("a world-file section needs a key and a reader");
  for (const auto& s : world_sections_)
    if (s->key == section->key)
      throw Error("world-file section '" + section->key + "' is registered twice");
  world_sections_.push_back(std::move(section));
}

void ModuleRegistry::RegisterEnvironmentFormat(
    std::shared_ptr<const EnvironmentFormatDescriptor> format) {
  if (!format || format->key.empty() || !format->read)
    throw Error("an environment map format needs a key and a reader");
  for (const auto& f : environment_formats_)
    if (f->key == format->key)
      throw Error("environment map format '" + format->key + "' is registered twice");
  environment_formats_.push_back(std::move(format));
}

void ModuleRegistry::RegisterModelSection(std::shared_ptr<const ModelSectionDescriptor> section) {
  if (!section || section->key.empty() || !section->read || !section->apply)
    throw Error("a model-file section needs a key, a reader and an apply step");
  for (const auto& s : model_sections_)
    if (s->key == section->key)
      throw Error("model-file section '" + section->key + "' is registered twice");
  model_sections_.push_back(std::move(section));
}

void ModuleRegistry::RegisterViewRecorder(std::shared_ptr<const ViewRecorderDescriptor> recorder) {
  if (!recorder || !recorder->add) throw Error("a view recorder needs an 'add' function");
  if (view_recorder_) throw Error("a view recorder is registered twice");
  view_recorder_ = std::move(recorder);
}

const VisionFilterDescriptor* ModuleRegistry::FindVisionFilter(std::string_view name) const {
  for (const auto& f : vision_filters_)
    if (f->name == name) return f.get();
  return nullptr;
}

const PluginSensorType* ModuleRegistry::FindPluginSensor(std::string_view name) const {
  for (const PluginSensorType& t : plugin_sensors_)
    if (t.name == name) return &t;
  return nullptr;
}

bool ModuleRegistry::HasPlugin(std::string_view path) const {
  for (const std::string& p : plugin_paths_)
    if (p == path) return true;
  return false;
}

std::unique_ptr<DynamicsBackend> ModuleRegistry::MakeDynamics(const std::string& name) const {
  for (const Dynamics& d : dynamics_)
    if (d.name == name) return d.factory();
  std::string known;
  for (const Dynamics& d : dynamics_) known += (known.empty() ? "" : ", ") + d.name;
  throw Error("unknown physics backend '" + name +
              "' (available: " + (known.empty() ? "(none)" : known) + ")");
}

const ModuleRegistry::BareLoop* ModuleRegistry::FindBareLoop(const std::string& physics) const {
  for (const Dynamics& d : dynamics_)
    if (d.name == physics && d.bare_loop) return &d.bare_loop;
  return nullptr;
}

bool ModuleRegistry::HasDynamics(const std::string& name) const {
  for (const Dynamics& d : dynamics_)
    if (d.name == name) return true;
  return false;
}

const DynamicsCapabilities& ModuleRegistry::dynamics_capabilities(const std::string& name) const {
  for (const Dynamics& d : dynamics_)
    if (d.name == name) return d.capabilities;
  MakeDynamics(name);  // throws: unknown, with the names there are
  throw Error("no dynamics backend '" + name + "'");
}

std::vector<std::string> ModuleRegistry::DynamicsNames() const {
  std::vector<std::string> out;
  for (const Dynamics& d : dynamics_) out.push_back(d.name);
  return out;
}

}  // namespace swarmsim
