// swarmsim modules and swarmsim version: what this program holds.
#include <CLI/CLI.hpp>
#include <iostream>

#include "framework/object_type.h"
#include "framework/registry.h"
#include "swarm/cli/commands.h"
#include "swarm/run/version.h"

namespace swarmsim::cli {

CLI::App* AddModulesCommand(CLI::App* app) {
  return app->add_subcommand("modules", "List the registered modules");
}

int ModulesCommand(const ModuleRegistry& registry) {
  // The built-in object types (framework/types/), then every registered
  // module (object types of modules and plugins among them).
  for (const ObjectTypeDescriptor* type : CoreObjectTypes())
    std::cout << "object type\t" << type->name << "\tbuilt-in\t" << type->description << "\n";
  for (const ModuleInfo& m : registry.modules())
    std::cout << m.kind << "\t" << m.name << "\t" << m.version << "\t" << m.description << "\n";
  return 0;
}

CLI::App* AddVersionCommand(CLI::App* app) {
  return app->add_subcommand("version", "Print the version");
}

int VersionCommand() {
  std::cout << "swarmsim " << Version() << "\n";
  return 0;
}

}  // namespace swarmsim::cli
