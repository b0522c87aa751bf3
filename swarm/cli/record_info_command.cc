// swarmsim record-info DIR: what a run's recording holds (swarm/record/reader.h),
// every step record decoded, so a damaged file shows here before a viewer opens it.
#include <CLI/CLI.hpp>
#include <iostream>

#include "framework/error.h"
#include "framework/utf8.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/record/reader.h"

namespace swarmsim::cli {

CLI::App* AddRecordInfoCommand(CLI::App* app, std::string* path) {
  CLI::App* info = app->add_subcommand(
      "record-info", "Check and summarise a run's recording (DIR/recording.swrec, from --record)");
  info->add_option("dir", *path, "A run's output folder, or a .swrec file")->required();
  return info;
}

int RecordInfoCommand(const std::string& path) {
  try {
    record::RecordingPlayer player(path);
    int64_t decoded = 0;
    while (player.Next()) ++decoded;
    std::cout << ValidUtf8(player.info().Describe()) << "\n"
              << "objects         " << player.object_count() << " in the last scene\n"
              << "decoded         " << decoded << " step records\n";
  } catch (const Error& e) {
    std::cerr << "error: " << ValidUtf8(e.what()) << "\n";
    return kExitBadInput;
  }
  return 0;
}

}  // namespace swarmsim::cli
