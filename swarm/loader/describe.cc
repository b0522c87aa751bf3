#include "swarm/loader/describe.h"

#include <string>

#include "framework/environment.h"
#include "framework/parameters.h"
#include "framework/scene.h"

namespace swarmsim {

void PrintDescription(const LoadedWorld& w, std::ostream& out) {
  const WorldSettings& s = w.world->settings();
  out << "world: " << s.file << "\n"
      << "physics: " << s.physics << ", time step " << s.time_step << " s, seed " << s.seed << "\n"
      << "main script: " << (s.main_script ? s.main_script->path : "(default step)") << "\n";
  if (s.robots_per_lua_state > 1)
    out << "Lua states: " << s.robots_per_lua_state
        << " robots a state (simulation.robots_per_lua_state)\n";
  // The world's modules (framework/module.h), in the order they run within a phase.
  out << "modules:";
  for (const std::string& name : w.world->module_names()) out << " " << name;
  out << "\n";
  if (const EnvironmentMap* map = w.world->scene().environment())
    out << "environment: " << map->source << ", " << map->boxes.size() << " occupied voxels of "
        << map->resolution << " m, from (" << map->lo.x << ", " << map->lo.y << ", " << map->lo.z
        << ") to (" << map->hi.x << ", " << map->hi.y << ", " << map->hi.z << ") m\n";
  for (const std::string& warning : w.warnings) out << "warning: " << warning << "\n";
  if (!w.world->parameters().empty()) {
    out << "world parameters:\n";
    for (const auto& [name, value] : w.world->parameters())
      out << "  " << name << " = " << ShowParamValue(value) << "\n";
  }
  for (const ModelSummary& m : w.models) {
    out << "\nmodel " << m.name << " (" << m.file << "): " << m.count
        << (m.count == 1 ? " copy" : " copies");
    if (m.scale != 1) out << ", scale " << m.scale;
    if (m.spatial_order) out << ", numbered along the region (order: spatial)";
    out << "\n";
    for (const std::string& line : m.imported) out << "  " << line << "\n";
    for (const std::string& script : m.scripts) out << "  script: " << script << "\n";
    if (!m.python.file.empty())
      out << "  python controller: " << m.python.file.string() << ":" << m.python.function
          << (m.python.keep_scripts ? " (beside the Lua scripts)" : " (instead of the Lua scripts)")
          << "\n";
    if (!m.native_controller.empty()) out << "  native controller: " << m.native_controller << "\n";
    for (const std::string& module : m.modules) out << "  module: " << module << "\n";
    if (m.parameters.empty()) out << "  parameters: none\n";
    for (const ParameterSummary& p : m.parameters) {
      out << "  " << m.name << "." << p.name << " = " << p.value;
      // Unit "1" (SI's for a ratio or a factor) reads as a stray digit after the value.
      if (!p.unit.empty() && p.unit != "1") out << " " << p.unit;
      out << "  (default " << p.default_value;
      if (!p.range.empty()) out << ", range " << p.range;
      out << ")";
      if (!p.description.empty()) out << "  " << p.description;
      out << "\n";
    }
    for (const auto& [index, values] : m.instances)
      out << "  copy " << index << " of this entry: " << (values.empty() ? "(as above)" : values)
          << "\n";
  }
}

}  // namespace swarmsim
