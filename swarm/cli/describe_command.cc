// swarmsim describe WORLD: the world's settings, its models, their
// parameters (with --set applied) and scripts, without running anything.
#include <CLI/CLI.hpp>
#include <iostream>
#include <ostream>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/utf8.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/loader/describe.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim::cli {

CLI::App* AddDescribeCommand(CLI::App* app, DescribeArgs* args) {
  CLI::App* describe =
      app->add_subcommand("describe", "List a world's models, their parameters and scripts");
  describe->add_option("world", args->world, "World file (YAML)")->required();
  describe
      ->add_option("--set", args->sets,
                   "Override a parameter (world NAME or MODEL.NAME); repeat for more: "
                   "--set a=1 --set b=2")
      ->option_text("NAME=VALUE")
      ->allow_extra_args(false);
  describe
      ->add_option("--package-path", args->package_path,
                   "A folder holding the ROS packages of URDF models' package:// URIs; repeat "
                   "for more")
      ->allow_extra_args(false);
  return describe;
}

int DescribeCommand(const DescribeArgs& args, const ModuleRegistry& registry) {
  LoadOptions load;
  load.overrides = ParseSets(args.sets);
  load.plugin_directories = PluginDirectories();
  load.package_path.assign(args.package_path.begin(), args.package_path.end());
  try {
    const LoadedWorld w = LoadWorld(args.world, load, registry);
    PrintDescription(w, std::cout);
  } catch (const Error& e) {
    std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
    return kExitBadInput;
  }
  return 0;
}

}  // namespace swarmsim::cli
