// swarmsim view DIR: serve the viewer page for a run's recording, or write
// it as one self-contained HTML file (--export).
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "framework/error.h"
#include "framework/regular_file.h"
#include "framework/utf8.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/record/reader.h"
#include "swarm/run/output_folder.h"
#include "swarm/viewer/page.h"
#include "swarm/viewer/server.h"

namespace swarmsim::cli {

CLI::App* AddViewCommand(CLI::App* app, ViewArgs* args) {
  CLI::App* view = app->add_subcommand(
      "view", "Watch a recorded run (swarmsim run WORLD --out DIR --record) in the browser");
  view->add_option("folder", args->folder, "The run's output folder (holds recording.swrec)")
      ->required()
      ->check(NonEmpty("a folder"));
  view->add_option("--port", args->port, "Port to listen on (default 8600; 0: a free one)")
      ->transform(WholeNumberCheck(0, 65535, ""));
  view->add_option("--host", args->host,
                   "Address to listen on (default 127.0.0.1: this machine only)")
      ->check(NonEmpty("an address"));
  view->add_option("--export", args->export_file,
                   "Write one self-contained HTML file (page, three.js, recording) that plays "
                   "offline from disk, instead of serving")
      ->option_text("FILE.html")
      ->check(NonEmpty("a file"));
  view->add_option("--mesh-budget", args->mesh_budget,
                   "Triangles of meshes (each copy counted) the page draws in full; past it, "
                   "simplified or boxes (default 1000000, 100000 on a software renderer; the "
                   "page's ?mesh_budget=N overrides it)")
      ->transform(WholeNumberCheck(0, int64_t{1} << 40, ""));
  return view;
}

int BindViewServer(const std::string& host, int port, viewer::Server* server) {
  try {
    server->Bind(host, port);
  } catch (const Error& e) {
    std::cerr << "error: " << ValidUtf8(e.what()) << "\n";
    return kExitRunError;
  }
  std::cout << "swarmsim view: " << server->Address() << " (Ctrl-C to stop)" << std::endl;
  return 0;
}

int ViewCommand(const ViewArgs& args) {
  // The folder and its recording: missing, corrupt or of a newer format are
  // the user's to fix; a truncated one (a run in progress, or killed) is
  // shown up to its last whole step.
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::is_directory(args.folder, error)) {
    std::cerr << "error: '" << ValidUtf8(args.folder)
              << "' is not a folder: give the output folder of a run (swarmsim run WORLD --out "
                 "DIR --record)\n";
    return kExitBadInput;
  }
  // The page is written beside its name and renamed over it: not over the
  // run's own files (it replaced the recording it was made from), a device
  // or a pipe.
  if (!args.export_file.empty()) {
    const fs::path target = fs::weakly_canonical(fs::absolute(args.export_file, error), error);
    const fs::path folder = fs::weakly_canonical(fs::absolute(args.folder, error), error);
    for (const char* own : kRunOwnFiles)
      if (target == folder / own) {
        std::cerr << "error: --export: '" << ValidUtf8(args.export_file) << "' is the run's own "
                  << own << " in '" << ValidUtf8(args.folder) << "': name another file\n";
        return kExitBadInput;
      }
    if (const std::string why = NotAnOrdinaryFile(target); !why.empty()) {
      std::cerr << "error: --export: '" << ValidUtf8(args.export_file) << "': " << why
                << ": name a file\n";
      return kExitBadInput;
    }
  }
  // Serving scans the chunks (and the JSON of header, scene and end chunks):
  // the page decodes the step records as it plays, following a run in
  // progress. An export is checked as record-info checks, every step record
  // decoded, so a file that plays nowhere is not passed on.
  record::RecordingInfo info;
  try {
    if (args.export_file.empty()) {
      info = record::ScanRecording(args.folder);
    } else {
      record::RecordingPlayer player(args.folder);
      while (player.Next()) {
      }
      info = player.info();
    }
  } catch (const Error& e) {
    std::cerr << "error: " << ValidUtf8(e.what()) << "\n";
    return kExitBadInput;
  }
  std::cerr << ValidUtf8(info.Describe()) << "\n";
  if (!args.export_file.empty()) {
    try {
      viewer::ExportFolder(args.folder, info.valid_size, args.export_file,
                           {.mesh_budget = args.mesh_budget});
    } catch (const Error& e) {
      std::cerr << "error: " << ValidUtf8(e.what()) << "\n";
      return kExitRunError;
    }
    std::cout << "swarmsim view: wrote " << args.export_file << " ("
              << fs::file_size(args.export_file, error) << " bytes)\n";
    return 0;
  }
  viewer::Server server(args.folder, {.mesh_budget = args.mesh_budget});
  if (const int code = BindViewServer(args.host, args.port, &server)) return code;
  server.Run();
  return 0;
}

}  // namespace swarmsim::cli
