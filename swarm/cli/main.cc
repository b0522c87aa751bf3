// The swarmsim command-line program: declares the commands (commands.h),
// parses the command line and calls the command that was given.
#include <pthread.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/utf8.h"
#include "modules/builtin.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/cli/parse_error.h"
#include "swarm/run/huge_pages.h"
#include "swarm/run/version.h"

namespace swarmsim::cli {
namespace {

int Main(int argc, char** argv) {
  CLI::App app{"swarmsim " + std::string(Version()) +
               ": a headless, swarm-scale robot simulator.\n"
               "Lua-controlled robot models, copied by the thousand, stepped in parallel."};
  app.require_subcommand(1);
  app.set_version_flag("--version", Version());

  // The commands, in the order --help lists them.
  RunArgs run_args;
  AddRunCommand(&app, &run_args);
  BenchArgs bench_args;
  const CLI::App* bench = AddBenchCommand(&app, &bench_args);
  SweepArgs sweep_args;
  const CLI::App* sweep = AddSweepCommand(&app, &sweep_args);
  ReportArgs report_args;
  const CLI::App* report = AddReportCommand(&app, &report_args);
  MergeArgs merge_args;
  const CLI::App* merge = AddMergeCommand(&app, &merge_args);
  ViewArgs view_args;
  const CLI::App* view = AddViewCommand(&app, &view_args);
  const CLI::App* modules = AddModulesCommand(&app);
  DescribeArgs describe_args;
  const CLI::App* describe = AddDescribeCommand(&app, &describe_args);
  const CLI::App* version = AddVersionCommand(&app);
  std::string record_info_path;
  const CLI::App* record_info = AddRecordInfoCommand(&app, &record_info_path);
  KilobotArgs kilobot_args;
  const CLI::App* kilobot = AddKilobotCommand(&app, &kilobot_args);

  const std::vector<std::string> args(argv + std::min(argc, 1), argv + argc);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // An empty list entry first: CLI11's own message for `--robots ,` is vaguer.
    const std::string empty_entry = EmptyListEntry(args);
    std::cerr << (empty_entry.empty() ? ParseErrorMessage(app, args, e) : empty_entry);
    return kExitBadInput;
  }
  // `bench --robots 1000,,2` parses (CLI11 drops the empty entry): refused.
  if (const std::string message = EmptyListEntry(args); !message.empty()) {
    std::cerr << message;
    return kExitBadInput;
  }
  // `run --set a=1 b=2` parses (b=2 as the world) but is the same mistake.
  if (const std::string message = SecondValueOfRepeatable(args); !message.empty()) {
    std::cerr << message;
    return kExitBadInput;
  }

  // A file-size limit (ulimit -f) makes a write fail with EFBIG, reported
  // like a full disk, instead of killing the program mid-write.
  std::signal(SIGXFSZ, SIG_IGN);

  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);

  if (*version) return VersionCommand();
  if (*record_info) return RecordInfoCommand(record_info_path);
  if (*kilobot) return KilobotCommand(kilobot_args);
  if (*describe) return DescribeCommand(describe_args, registry);
  if (*modules) return ModulesCommand(registry);
  if (*view) return ViewCommand(view_args);
  if (*sweep) return SweepCommand(sweep_args, CommandLine(argc, argv));
  if (*report) return ReportCommand(report_args);
  if (*merge) return MergeCommand(merge_args);
  if (*bench) return BenchCommand(bench_args, *bench);
  return RunCommand(run_args, CommandLine(argc, argv), &registry);
}

}  // namespace
}  // namespace swarmsim::cli

namespace {

// Main, its errors printed: the exit status.
int MainReporting(int argc, char** argv) {
  try {
    return swarmsim::cli::Main(argc, argv);
  } catch (const swarmsim::Error& e) {
    std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // Out of memory where nothing named it: a fixed text, which needs none.
    std::fputs(
        "error: out of memory (the machine, a ulimit or --max-memory gave no more; README, \"A "
        "world that does not fit\")\n",
        stderr);
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
    return 1;
  }
}

struct MainCall {
  int argc;
  char** argv;
  int code;
};

extern "C" void* CallMain(void* call) {
  auto* c = static_cast<MainCall*>(call);
  c->code = MainReporting(c->argc, c->argv);
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  const bool deep_enough = swarmsim::RoomForDeepCalls();
  swarmsim::RestartWithHugePages(argv);
  swarmsim::TuneMalloc();
  // A hard `ulimit -s` too low for Lua's deepest C recursion (bash's
  // `ulimit -s 256` sets both limits): the program runs on a thread of its
  // own with the stack it needs (a thread's stack is not bound by the
  // limit), so that a script's deep recursion is its error, not a segfault.
  if (!deep_enough) {
    MainCall call{argc, argv, 1};
    pthread_attr_t attr;
    pthread_t thread;
    if (pthread_attr_init(&attr) == 0 &&
        pthread_attr_setstacksize(&attr, swarmsim::kStackForDeepCalls) == 0 &&
        pthread_create(&thread, &attr, CallMain, &call) == 0) {
      pthread_attr_destroy(&attr);
      pthread_join(thread, nullptr);
      return call.code;
    }
  }
  return MainReporting(argc, argv);
}
