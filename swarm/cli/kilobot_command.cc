// swarmsim kilobot build prog.c [-o out.so] [--name NAME] [-- cc flags]:
// a Kilobot program, compiled unchanged, as a plugin with one native
// controller (swarm/kilobot/build.h).
#include <CLI/CLI.hpp>
#include <iostream>

#include "framework/error.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/kilobot/build.h"

namespace swarmsim::cli {

CLI::App* AddKilobotCommand(CLI::App* app, KilobotArgs* args) {
  CLI::App* kilobot =
      app->add_subcommand("kilobot", "Kilobot programs (kilolib's API) as native controllers");
  kilobot->require_subcommand(1);
  CLI::App* build = kilobot->add_subcommand(
      "build",
      "Compile a Kilobot program (prog.c, unchanged) into NAME.so, a plugin whose native "
      "controller NAME runs it on each robot (worlds/README.md: Kilobot)");
  build->add_option("source", args->options.source, "The program (C, #include <kilolib.h>)")
      ->required();
  build->add_option("cc_flags", args->options.cc_flags,
                    "After --: flags for the C compiler ($CC, default cc)");
  build->add_option("-o,--output", args->options.output,
                    "The plugin to write (default: NAME.so beside the source)");
  build->add_option("--name", args->options.name,
                    "The controller's name (default: the source's file name without .c)");
  build->add_flag("-q,--quiet", args->options.quiet, "Print nothing on success");
  return kilobot;
}

int KilobotCommand(const KilobotArgs& args) {
  try {
    return kilobot::Build(args.options);
  } catch (const Error& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
}

}  // namespace swarmsim::cli
