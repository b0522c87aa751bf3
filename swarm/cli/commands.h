// The commands of the `swarmsim` program. Each has what its command line
// gives it (the *Args), an Add*Command that declares its options on the
// program's CLI::App, and one function that does it and returns the exit
// code. main.cc adds them in the order `swarmsim --help` lists them and
// calls the one that was given.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "swarm/bench/scaling.h"
#include "swarm/kilobot/build.h"
#include "swarm/sweep/report.h"
#include "swarm/sweep/sweep.h"

namespace CLI {
class App;
}  // namespace CLI

namespace swarmsim {
class ModuleRegistry;
}  // namespace swarmsim
namespace swarmsim::viewer {
class Server;
}  // namespace swarmsim::viewer

namespace swarmsim::cli {

// swarmsim run WORLD (run_command.cc)
struct RunArgs {
  std::string world_file;
  int64_t steps = -1;    // -1: not given
  double duration = -1;  // s; -1: not given
  int threads = 0;       // 0: all cores
  std::optional<uint64_t> seed;
  std::vector<std::string> sets;  // NAME=VALUE
  std::string out_dir;
  bool hash = false, quiet = false;
  bool progress = false;  // --progress: the loading line also when stderr is not a terminal
  bool trust_scripts = false;
  std::string max_memory;  // --max-memory SIZE; empty: what the machine has
  std::vector<std::string> plugins;
  std::vector<std::string> package_path;  // --package-path: URDF packages' folders
  // Snapshots and video (framework/view_recorder.h).
  int64_t snapshot_every = 0;             // 0: none
  std::string camera;                     // empty: the arena seen from above
  bool video = false;                     // --video given
  std::string video_file;                 // its FILE; empty: DIR/video.mp4
  int video_width = 0, video_height = 0;  // --video-size; 0: the view's default
  double video_fps = 30;
  bool no_rays = false;  // --no-rays: snapshots and video without proximity sensors' rays
  bool record = false;   // --record: DIR/recording.swrec (swarm/record/writer.h)
  // --view: record, and serve DIR to the viewer page while the run goes.
  bool view = false;
  int view_port = 8600;  // 0: a free port
  std::string view_host = "127.0.0.1";
  // World snapshots (framework/world_state.h): --save-state FILE at the end
  // or after step --save-state-at; --load-state FILE to continue from one.
  std::string save_state, load_state;
  int64_t save_state_at = -1;  // -1: at the end
};
CLI::App* AddRunCommand(CLI::App* app, RunArgs* args);
// Loads the world (the plugins first into `registry`) and runs it.
int RunCommand(const RunArgs& args, const std::string& command_line, ModuleRegistry* registry);

// swarmsim kilobot build PROG.c (kilobot_command.cc)
struct KilobotArgs {
  kilobot::BuildOptions options;
};
CLI::App* AddKilobotCommand(CLI::App* app, KilobotArgs* args);
int KilobotCommand(const KilobotArgs& args);

// swarmsim record-info DIR (record_info_command.cc)
CLI::App* AddRecordInfoCommand(CLI::App* app, std::string* path);
int RecordInfoCommand(const std::string& path);

// swarmsim bench (bench_command.cc)
struct BenchArgs {
  BenchOptions options;
  std::string child_config;  // internal: measure one configuration in this process
  int child_robots = 0, child_threads = 1;
  bool scaling = false;  // --scaling
  ScalingOptions scaling_options;
  bool scaling_robots = false;       // --scaling-robots
  std::vector<std::string> configs;  // --configs lua,cpp,planar-lua,planar-cpp
  int repeat = 1;                    // --repeat N (with --scaling-robots)
};
CLI::App* AddBenchCommand(CLI::App* app, BenchArgs* args);
// `command`: what AddBenchCommand returned (was --threads given?).
int BenchCommand(BenchArgs args, const CLI::App& command);

// swarmsim sweep WORLD, report DB, merge OUT IN... (sweep_commands.cc)
struct SweepArgs {
  SweepOptions options;
  std::string shard;     // i/n
  int64_t steps = -1;    // -1: not given
  double duration = -1;  // s; -1: not given
};
CLI::App* AddSweepCommand(CLI::App* app, SweepArgs* args);
int SweepCommand(SweepArgs args, const std::string& command_line);

struct ReportArgs {
  ReportOptions options;
  std::string csv, plot;  // empty: not given
};
CLI::App* AddReportCommand(CLI::App* app, ReportArgs* args);
int ReportCommand(ReportArgs args);

struct MergeArgs {
  std::string out;
  std::vector<std::string> inputs;
  bool allow_changed_world = false;
};
CLI::App* AddMergeCommand(CLI::App* app, MergeArgs* args);
int MergeCommand(const MergeArgs& args);

// swarmsim modules, version (info_commands.cc)
CLI::App* AddModulesCommand(CLI::App* app);
int ModulesCommand(const ModuleRegistry& registry);
CLI::App* AddVersionCommand(CLI::App* app);
int VersionCommand();

// swarmsim describe WORLD (describe_command.cc)
struct DescribeArgs {
  std::string world;
  std::vector<std::string> sets;          // NAME=VALUE
  std::vector<std::string> package_path;  // --package-path
};
CLI::App* AddDescribeCommand(CLI::App* app, DescribeArgs* args);
int DescribeCommand(const DescribeArgs& args, const ModuleRegistry& registry);

// swarmsim view DIR (view_command.cc)
struct ViewArgs {
  std::string folder;
  std::string host = "127.0.0.1";
  int port = 8600;           // 0: a free port
  std::string export_file;   // --export FILE.html; empty: serve
  int64_t mesh_budget = -1;  // --mesh-budget: triangles of meshes drawn in full; -1: the page's
};
CLI::App* AddViewCommand(CLI::App* app, ViewArgs* args);
int ViewCommand(const ViewArgs& args);
// Binds `server` and prints its address ("swarmsim view: http://...");
// prints why not and returns kExitRunError when it cannot.
int BindViewServer(const std::string& host, int port, viewer::Server* server);

}  // namespace swarmsim::cli
