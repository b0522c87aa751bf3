#include "framework/registry.h"

#include <cctype>

#include "framework/calculation_module.h"
#include "framework/dynamics_backend.h"
#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/proximity_backend.h"

namespace swarmsim {

void ModuleRegistry::RegisterDynamics(ModuleInfo info, DynamicsFactory factory) {
  info.kind = "dynamics";
  dynamics_.emplace_back(info.name, std::move(factory));
  modules_.push_back(std::move(info));
}

void ModuleRegistry::RegisterProximity(ModuleInfo info, ProximityFactory factory) {
  info.kind = "proximity";
  proximity_.emplace_back(info.name, std::move(factory));
  modules_.push_back(std::move(info));
}

void ModuleRegistry::RegisterCalculation(ModuleInfo info, CalculationFactory factory) {
  info.kind = "calculation";
  calculation_.emplace_back(info.name, std::move(factory));
  modules_.push_back(std::move(info));
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
  if (callback.phase < 0 || callback.phase >= kSwarmsimPhaseCount || callback.function == nullptr)
    throw Error("phase callback '" + callback.name + "' has an unknown phase or no function");
  info.kind = "callback";
  modules_.push_back(std::move(info));
  phase_callbacks_.push_back(std::move(callback));
}

void ModuleRegistry::RegisterPluginSensor(ModuleInfo info, PluginSensorType type) {
  if (type.name.empty() || type.function == nullptr)
    throw Error("a plugin sensor type needs a name and a sense function");
  if (FindPluginSensor(type.name) != nullptr)
    throw Error("plugin sensor type '" + type.name + "' is registered twice");
  info.kind = "sensor";
  modules_.push_back(std::move(info));
  plugin_sensors_.push_back(std::move(type));
}

void ModuleRegistry::RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor> type) {
  if (!type || type->name == nullptr || *type->name == '\0')
    throw Error("an object type needs a name");
  const std::string name = type->name;
  for (const ObjectTypeDescriptor* t : CoreObjectTypes())
    if (name == t->name) throw Error("object type '" + name + "' is a built-in type");
  for (const ObjectTypeDescriptor* t : object_types_)
    if (name == t->name) throw Error("object type '" + name + "' is registered twice");
  modules_.push_back({"object type", name, "", type->description ? type->description : ""});
  object_types_.push_back(type.get());
  owned_object_types_.push_back(std::move(type));
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

template <typename Factories>
static std::string Known(const Factories& factories) {
  std::string out;
  for (const auto& [name, f] : factories) out += (out.empty() ? "" : ", ") + name;
  return out.empty() ? "(none)" : out;
}

std::unique_ptr<DynamicsBackend> ModuleRegistry::MakeDynamics(const std::string& name) const {
  for (const auto& [n, f] : dynamics_)
    if (n == name) return f();
  throw Error("unknown physics backend '" + name + "' (available: " + Known(dynamics_) + ")");
}

std::unique_ptr<ProximityBackend> ModuleRegistry::MakeProximity(const std::string& name) const {
  for (const auto& [n, f] : proximity_)
    if (n == name) return f();
  throw Error("unknown proximity module '" + name + "' (available: " + Known(proximity_) + ")");
}

std::unique_ptr<CalculationModule> ModuleRegistry::MakeCalculation(const std::string& name) const {
  for (const auto& [n, f] : calculation_)
    if (n == name) return f();
  throw Error("unknown calculation module '" + name + "' (available: " + Known(calculation_) + ")");
}

bool ModuleRegistry::HasDynamics(const std::string& name) const {
  for (const auto& [n, f] : dynamics_)
    if (n == name) return true;
  return false;
}

std::vector<std::string> ModuleRegistry::DynamicsNames() const {
  std::vector<std::string> out;
  for (const auto& [n, f] : dynamics_) out.push_back(n);
  return out;
}

}  // namespace swarmsim
