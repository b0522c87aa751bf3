// swarmsim run WORLD: load the world, decide the run length, run it.
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "framework/error.h"
#include "framework/memory_forecast.h"
#include "framework/plugin_loader.h"
#include "framework/registry.h"
#include "framework/regular_file.h"
#include "framework/sanitizers.h"
#include "framework/scheduler.h"
#include "framework/utf8.h"
#include "framework/view_recorder.h"
#include "swarm/cli/commands.h"
#include "swarm/cli/options.h"
#include "swarm/loader/world_loader.h"
#include "swarm/record/writer.h"
#include "swarm/run/file_lock.h"
#include "swarm/run/output_folder.h"
#include "swarm/run/runner.h"
#include "swarm/run/stop_signals.h"
#include "swarm/viewer/server.h"

namespace swarmsim::cli {
namespace {

// The line on stderr while a large world loads (--progress, or stderr a
// terminal; never with --quiet), one stage after another:
// "loading: placing robots: 450,560 of 1,000,000",
// "loading: 1,000,000 robots placed; populating their memory: 3.2 of 9.6 GiB",
// "loading: 1,000,000 robots placed; building them",
// "loading: 45,056 of 100,000 robots built",
// redrawn in place on a terminal (a new line each time otherwise) at most
// twice a second, once the load has taken half a second; then, for a world
// that showed it (always with --progress), "loaded 100,000 robots in 3.4 s;
// starting them", and the stages of the start (Starting). The run's own
// progress follows.
class LoadProgress {
 public:
  using Stage = LoadOptions::LoadStage;
  LoadProgress(bool forced, bool tty) : forced_(forced), tty_(tty) {}

  void Loading(Stage stage, int64_t done, int64_t total) {
    if (stage != Stage::kPopulating) total_ = total;
    const double now = Seconds();
    if (now < 0.5 || (shown_ && now - last_ < 0.5)) return;
    last_ = now;
    shown_ = true;
    std::cerr << (tty_ ? "\r" : "") << "loading: ";
    if (stage == Stage::kPlacing) {
      std::cerr << "placing robots: " << GroupThousands(done) << " of " << GroupThousands(total);
    } else if (stage == Stage::kPopulating) {
      // Each robot's rows, reserved at once and populated on every thread.
      const bool gib = total >= (int64_t{1} << 30);
      const double unit = gib ? double(int64_t{1} << 30) : double(int64_t{1} << 20);
      std::cerr << GroupThousands(total_)
                << " robots placed; populating their memory: " << std::fixed
                << std::setprecision(gib ? 1 : 0) << static_cast<double>(done) / unit << " of "
                << static_cast<double>(total) / unit << std::defaultfloat
                << (gib ? " GiB" : " MiB");
    } else if (done == 0) {
      std::cerr << GroupThousands(total) << " robots placed; building them";
    } else {
      std::cerr << GroupThousands(done) << " of " << GroupThousands(total) << " robots built";
    }
    std::cerr << (tty_ ? "\033[K" : "\n") << std::flush;
  }
  // The load failed: an error message goes on a line of its own.
  void Abandon() {
    if (tty_ && shown_) std::cerr << "\n";
  }
  // The world's start begins `stage` ("": it has started). For a world
  // whose load was shown (or --progress): on a terminal, the stage under
  // way, redrawn in place ("starting: module proximity (at 1.6 s)") and
  // cleared at the end; otherwise a line for each stage that took 0.05 s or
  // more as it ends ("started module proximity in 2.2 s") and the total
  // ("started in 3.9 s").
  void Starting(const std::string& stage) {
    if (!shown_ && !forced_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!starting_) starting_ = stage_start_ = now;
    const auto seconds = [](std::chrono::steady_clock::duration d) {
      std::ostringstream text;
      text << std::fixed << std::setprecision(1) << std::chrono::duration<double>(d).count();
      return text.str();
    };
    if (tty_) {
      // The line of the stage before, rewritten (the cursor stays below it,
      // so that an error in the start comes on a line of its own).
      if (stage_shown_) std::cerr << "\033[A\r";
      if (!stage.empty())
        std::cerr << "starting: " << swarmsim::ValidUtf8(stage) << " (at "
                  << seconds(now - *starting_) << " s)\033[K\n";
      else
        std::cerr << "\033[K";
      std::cerr << std::flush;
      stage_shown_ = !stage.empty();
    } else {
      if (!stage_.empty() && now - stage_start_ >= std::chrono::milliseconds(50))
        std::cerr << "started " << swarmsim::ValidUtf8(stage_) << " in "
                  << seconds(now - stage_start_) << " s\n";
      if (stage.empty()) std::cerr << "started in " << seconds(now - *starting_) << " s\n";
      std::cerr << std::flush;
    }
    stage_ = stage;
    stage_start_ = now;
  }
  void Loaded() {
    if (!shown_ && !forced_) return;
    std::cerr << (tty_ && shown_ ? "\r" : "") << "loaded " << GroupThousands(total_)
              << " robots in " << std::fixed << std::setprecision(1) << Seconds()
              << std::defaultfloat << " s; starting them" << (tty_ && shown_ ? "\033[K" : "")
              << "\n"
              << std::flush;
  }

 private:
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  const bool forced_, tty_;
  bool shown_ = false;
  double last_ = 0;
  int64_t total_ = 0;
  std::optional<std::chrono::steady_clock::time_point> starting_;  // the first stage's
  std::string stage_;                                              // under way
  bool stage_shown_ = false;                           // on a terminal: its line is the one above
  std::chrono::steady_clock::time_point stage_start_;  // its beginning
};

// The number of steps: --steps, else --duration rounded to whole time steps,
// else the world's own; nullopt and `*error` set when none fits.
std::optional<int64_t> RunLength(const RunArgs& args, const LoadedWorld& loaded,
                                 std::string* error) {
  if (args.steps >= 0) return args.steps;
  if (args.duration >= 0) {
    // The nearest whole number of steps; a duration under one step would run none.
    const double time_step = loaded.world->settings().time_step;
    if (args.duration > 0 && args.duration < time_step) {
      std::ostringstream message;
      message << "--duration " << args.duration << " s is shorter than one time step (" << time_step
              << " s)";
      *error = message.str();
      return std::nullopt;
    }
    const double step_count = StepsInDuration(args.duration, time_step);
    if (!(step_count <= 1e15)) {
      std::ostringstream message;
      message << "--duration " << args.duration << " s is " << step_count << " steps of "
              << time_step << " s; at most 1e15 steps";
      *error = message.str();
      return std::nullopt;
    }
    return static_cast<int64_t>(step_count);
  }
  if (loaded.steps) return *loaded.steps;
  *error = args.world_file + " gives no run length; pass --steps N or --duration SECONDS";
  return std::nullopt;
}

// --video-size WIDTHxHEIGHT, each side 1..4096 pixels.
bool ParseVideoSize(const std::string& text, int* width, int* height) {
  const size_t x = text.find_first_of("xX");
  if (x == std::string::npos) return false;
  const auto side = [](std::string_view digits, int* out) {
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), *out);
    return !digits.empty() && ec == std::errc() && end == digits.data() + digits.size() &&
           *out >= 1 && *out <= 4096;
  };
  const std::string_view all(text);
  return side(all.substr(0, x), width) && side(all.substr(x + 1), height);
}

// The recorder's settings from the command line; nullopt when none is asked for.
std::optional<ViewRecorderSettings> RecorderSettingsOf(const RunArgs& args, std::string* error) {
  const bool recording = args.snapshot_every > 0 || args.video;
  if (!recording) {
    if (!args.camera.empty()) *error = "--camera names the view of --snapshot-every or --video";
    if (args.video_width > 0) *error = "--video-size is the size of --snapshot-every or --video";
    if (args.no_rays) *error = "--no-rays hides the rays in --snapshot-every or --video";
    return std::nullopt;
  }
  ViewRecorderSettings settings;
  if (!args.out_dir.empty()) settings.out_dir = args.out_dir;
  settings.snapshot_every = args.snapshot_every;
  settings.camera = args.camera;
  settings.width = args.video_width;
  settings.height = args.video_height;
  settings.video_fps = args.video_fps;
  settings.rays = !args.no_rays;
  if (args.video) {
    if (!args.video_file.empty()) {
      settings.video = args.video_file;  // relative to the current folder, as typed
    } else if (!args.out_dir.empty()) {
      settings.video = std::filesystem::path(args.out_dir) / "video.mp4";
    } else {
      *error = "--video without a FILE writes DIR/video.mp4: pass --out DIR or --video FILE.mp4";
      return std::nullopt;
    }
  }
  return settings;
}

}  // namespace

CLI::App* AddRunCommand(CLI::App* app, RunArgs* args) {
  CLI::App* run = app->add_subcommand("run", "Run a world and print a summary");
  run->add_option("world", args->world_file, "World file (YAML)")->required();
  auto* steps_opt = run->add_option("--steps", args->steps, "Number of control steps to run")
                        ->transform(WholeNumberCheck(0, kInt64Max, "steps"));
  run->add_option("--duration", args->duration,
                  "Simulated seconds to run, rounded to the nearest whole number of time steps "
                  "(less than one step is an error)")
      ->check(NonNegativeCheck())
      ->excludes(steps_opt);
  run->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->transform(ThreadCountCheck());
  run->add_option("--seed", args->seed, "Random seed (overrides the world's)")
      ->transform(SeedCheck());
  run->add_option("--set", args->sets,
                  "Override a parameter (world NAME or MODEL.NAME); repeat for more: "
                  "--set a=1 --set b=2")
      ->option_text("NAME=VALUE")
      ->allow_extra_args(false);
  run->add_option("--out", args->out_dir, "Write summary.json and metrics.csv to this folder")
      ->check(NonEmpty("a folder"));
  run->add_flag("--hash", args->hash, "Print the final state hash");
  run->add_flag("--quiet", args->quiet, "No progress bar and no summary table");
  run->add_flag("--progress", args->progress,
                "Show loading progress (robots built) also when stderr is not a terminal");
  run->add_option("--plugin", args->plugins, "Load a plugin (shared library) before the world")
      ->allow_extra_args(false);
  run->add_option("--package-path", args->package_path,
                  "A folder holding the ROS packages of URDF models' package:// URIs (after the "
                  "world's package_path); repeat for more")
      ->allow_extra_args(false);
  run->add_option("--max-memory", args->max_memory,
                  "Refuse a world whose robot copies or Lua states would take the process past "
                  "SIZE (e.g. 8G); without it, past what the machine (or cgroup) has")
      ->check(MemorySizeCheck());
  run->add_flag("--trust-scripts", args->trust_scripts,
                "Lift the script sandbox: full Lua libraries (os, io, debug, package)");
  run->add_option("--snapshot-every", args->snapshot_every,
                  "Write a PNG of the view at step 0 and every N steps to "
                  "DIR/snapshots/step_NNNNNN.png (needs --out)")
      ->transform(WholeNumberCheck(1, kInt64Max, "steps"));
  auto* video = run->add_option("--video", args->video_file,
                                "Record an H.264 video of the view (default DIR/video.mp4 with "
                                "--out; a FILE is relative to the current folder)")
                    ->expected(0, 1)
                    ->option_text("[FILE.mp4]")
                    ->check(CLI::Validator(
                        [](std::string& text) -> std::string {
                          const std::string_view t(text);
                          if (!t.ends_with(".yaml") && !t.ends_with(".yml")) return "";
                          return "'" + text +
                                 "' is a .yaml name (a world or model file?): the video would "
                                 "be written there; name a FILE.mp4 (a world goes before "
                                 "--video)";
                        },
                        ""));
  run->add_option(
         "--camera", args->camera,
         "View of the snapshots and video: a camera or vision sensor (/cam, /footbot#3/eye) "
         "instead of the arena seen from above")
      ->check(NonEmpty("a camera's path"));
  run->add_option_function<std::string>(
         "--video-size",
         [args](const std::string& text) {
           ParseVideoSize(text, &args->video_width, &args->video_height);
         },
         "Pixels of the snapshots and video frames (default 640x480 for the arena, a camera's own "
         "resolution)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            int w = 0, h = 0;
            return ParseVideoSize(text, &w, &h)
                       ? ""
                       : "expected WIDTHxHEIGHT with each side 1..4096 pixels, got '" + text + "'";
          },
          "WxH"));
  run->add_option("--video-fps", args->video_fps,
                  "Video frames per simulated second (default 30): a frame every round(1 / (FPS "
                  "time_step)) steps, at least 1")
      ->check(NumberCheck(false))
      ->needs(video);
  run->add_flag("--no-rays", args->no_rays,
                "Snapshots and video without the sensors' rays (drawn by default: proximity "
                "sensors' rays, red where they detect something)");
  run->add_flag("--record", args->record,
                "Record the run for swarmsim view: DIR/recording.swrec (needs --out; a world's "
                "record: setting does the same)");
  auto* view = run->add_flag("--view", args->view,
                             "Record the run and watch it live: serves DIR to the viewer page "
                             "(swarmsim view) while the run goes, and after it until Ctrl-C");
  run->add_option("--view-port", args->view_port, "Port of --view (default 8600; 0: a free one)")
      ->transform(WholeNumberCheck(0, 65535, ""))
      ->needs(view);
  run->add_option("--view-host", args->view_host,
                  "Address --view listens on (default 127.0.0.1: this machine only)")
      ->check(NonEmpty("an address"))
      ->needs(view);
  auto* save_state =
      run->add_option("--save-state", args->save_state,
                      "Write the world's state to FILE at the end of the run (or after step "
                      "--save-state-at); --load-state continues from it. Worlds whose robots run "
                      "Lua scripts or native controllers are refused (README.md, Snapshots)")
          ->option_text("FILE")
          ->check(NonEmpty("a file"));
  run->add_option("--save-state-at", args->save_state_at,
                  "The step after which --save-state writes the state (the world's step count, "
                  "counted from 0 or from the step --load-state resumed at)")
      ->transform(WholeNumberCheck(0, kInt64Max, "steps"))
      ->needs(save_state);
  run->add_option("--load-state", args->load_state,
                  "Continue from the state --save-state wrote (a run of the same world file, "
                  "--set values and --seed); --steps then counts the steps run from there")
      ->option_text("FILE")
      ->check(NonEmpty("a file"));
  run->callback([args, video] { args->video = video->count() > 0; });
  return run;
}

namespace {

// Why a file the command line names (--video, --save-state) cannot be the
// one asked for: it is one of the run's own outputs (the command line would
// overwrite summary.json or metrics.csv with a video), the other flag's
// file, a folder, or (--save-state) in a folder that is not there. "" when
// it can be written.
std::string FileClash(const std::string& flag, const std::string& file, const RunArgs& args,
                      const std::string& other_flag, const std::string& other_file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path path = fs::weakly_canonical(fs::absolute(file, ec), ec);
  if (!args.out_dir.empty()) {
    const fs::path out = fs::weakly_canonical(fs::absolute(args.out_dir, ec), ec);
    std::vector<std::string> own_names(kRunOwnFiles.begin(), kRunOwnFiles.end());
    own_names.push_back("snapshots");
    for (const std::string& own : own_names)
      if (path == out / own)
        return flag + ": '" + file + "' is this run's own " + own + " (--out " + args.out_dir +
               "): name another file";
  }
  if (!other_file.empty() && path == fs::weakly_canonical(fs::absolute(other_file, ec), ec))
    return flag + ": '" + file + "' is " + other_flag + "'s file too: name two files";
  if (fs::is_directory(path, ec)) return flag + ": '" + file + "' is a folder: name a file";
  // The world file (overwritten by the state, exit 0), and for the state,
  // written beside its name and renamed over it, a device or a pipe
  // (--save-state /dev/null turned the system's /dev/null into a file).
  if (fs::equivalent(path, args.world_file, ec))
    return flag + ": '" + file + "' is the world file: name another file";
  if (flag == "--save-state")
    if (const std::string why = NotAnOrdinaryFile(path); !why.empty())
      return flag + ": '" + file + "': " + why + ": name a file";
  // A file there already that no video run wrote (a script, a model: the
  // video went over it with exit 0): an MP4 starts with its 'ftyp' box.
  if (flag == "--video" && fs::is_regular_file(path, ec) && fs::file_size(path, ec) > 0) {
    char head[8] = {};
    std::ifstream in(path, std::ios::binary);
    in.read(head, sizeof head);
    if (in.gcount() < 8 || std::string_view(head + 4, 4) != "ftyp")
      return flag + ": '" + file +
             "' is a file that is not a video: the video would go over it; name another "
             "file (or remove it first)";
  }
  // Its folder: there already, or --out (made before the run). (--video's
  // is checked as the recorder opens it, also before the run.)
  const fs::path folder = path.parent_path();
  const bool out_folder =
      !args.out_dir.empty() && folder == fs::weakly_canonical(fs::absolute(args.out_dir, ec), ec);
  if (flag == "--save-state" && !out_folder && !fs::is_directory(folder, ec))
    return flag + ": cannot write '" + file + "': there is no folder '" + folder.string() + "'";
  return "";
}

}  // namespace

int RunCommand(const RunArgs& args, const std::string& command_line, ModuleRegistry* registry) {
  // SIGINT, SIGTERM, SIGHUP from here on are noted, not fatal (see below,
  // where the load starts: the run ends as interrupted, with its summary).
  std::optional<StopSignals> stop_signals;
  stop_signals.emplace();
  // Files the command line names that would overwrite the run's own, or
  // cannot be written: a bad command line, before anything runs.
  {
    const std::string video = !args.video                ? ""
                              : !args.video_file.empty() ? args.video_file
                              : !args.out_dir.empty()
                                  ? (std::filesystem::path(args.out_dir) / "video.mp4").string()
                                  : "";
    for (const auto& [flag, file, other_flag, other] :
         {std::tuple{std::string("--video"), video, std::string("--save-state"), args.save_state},
          std::tuple{std::string("--save-state"), args.save_state, std::string("--video"),
                     video}}) {
      if (file.empty()) continue;
      if (const std::string clash = FileClash(flag, file, args, other_flag, other);
          !clash.empty()) {
        std::cerr << "error: " << swarmsim::ValidUtf8(clash) << "\n";
        return kExitBadInput;
      }
    }
  }
  RunOptions options;
  if (!args.out_dir.empty()) options.out_dir = args.out_dir;
  options.world_file = args.world_file;
  options.command_line = command_line;
  // --out must be a folder we can make: a bad one is a bad command line
  // (exit 2 before the run), not an error after the run's summary.
  // One run at a time writes into a folder (two mixed their metrics and
  // snapshots): DIR/.swarmsim-lock, held until this function returns. A
  // folder this user cannot write is found here too, before any work.
  std::optional<FileLock> out_lock;
  if (options.out_dir) {
    try {
      CreateOutputFolder(*options.out_dir);
      out_lock.emplace((*options.out_dir / ".swarmsim-lock").string());
    } catch (const Error& e) {
      std::cerr << "error: --out: " << swarmsim::ValidUtf8(e.what()) << "\n";
      return kExitBadInput;
    }
    // What the folder is now: moved or removed while the world loads, the
    // run says so (RunOptions::out_dir_inode).
    struct stat folder {};
    if (::stat(options.out_dir->c_str(), &folder) == 0) {
      options.out_dir_device = static_cast<uint64_t>(folder.st_dev);
      options.out_dir_inode = static_cast<uint64_t>(folder.st_ino);
    }
    if (!out_lock->held()) {
      std::cerr << "error: --out: another run"
                << (out_lock->holder().empty() ? "" : " (process " + out_lock->holder() + ")")
                << " is writing into '" << swarmsim::ValidUtf8(options.out_dir->string())
                << "'; wait for it to end, or pass another --out\n";
      return kExitBadInput;
    }
  }
  // A world that does not load (or does not fit the command line): with
  // --out, summary.json says so too, for a batch system watching the folder.
  const auto bad_input = [&](const std::string& message) {
    std::cerr << "error: " << swarmsim::ValidUtf8(message) << "\n";
    // A stop signal while the world loaded: "interrupted", the shell's 128 + N.
    const int sig = StopSignals::Received();
    if (options.out_dir) {
      const std::string reason =
          WriteErrorSummary(options, message, sig != 0 ? "interrupted" : "error");
      if (!reason.empty())
        std::cerr << "error: cannot write '" << (*options.out_dir / "summary.json").string()
                  << "': " << reason << "\n";
    }
    return sig != 0 ? 128 + sig : kExitBadInput;
  };
  // SIGINT, SIGTERM, SIGHUP while a large world loads (caught since the
  // start of this function): the load stops between model copies (or inside
  // a large mesh file's read) and the run ends as interrupted, with its
  // summary.json. Held until the program exits (the run's own nest inside
  // and keep a signal noted in between); only --view's serving after the run
  // lets them act as usual again (it ends with Ctrl-C).
  LoadOptions load;
  load.seed = args.seed;
  load.threads = args.threads;
  if (!args.out_dir.empty()) load.output_directory = args.out_dir;
  load.trust_scripts = args.trust_scripts;
  if (!args.max_memory.empty()) ParseMemorySize(args.max_memory, &load.max_memory);
  load.plugin_directories = PluginDirectories();
  load.package_path.assign(args.package_path.begin(), args.package_path.end());
  load.check_stop = [] {
    if (const int sig = StopSignals::Received(); sig != 0)
      throw Error(std::string("interrupted by SIG") + sigabbrev_np(sig) +
                  " while the world was loading");
  };
  load.note = [](const std::string& note) {
    std::cerr << "note: " << swarmsim::ValidUtf8(note) << std::endl;
  };
  std::optional<LoadProgress> load_progress;
  if (!args.quiet && (args.progress || isatty(STDERR_FILENO))) {
    load_progress.emplace(args.progress, isatty(STDERR_FILENO) != 0);
    load.progress = [&](LoadOptions::LoadStage stage, int64_t done, int64_t total) {
      load_progress->Loading(stage, done, total);
    };
  }
  LoadedWorld loaded;
  const auto load_start = std::chrono::steady_clock::now();
  try {
    load.overrides = ParseSets(args.sets);
    options.overrides = load.overrides;
    for (const std::string& plugin : args.plugins) LoadPlugin(plugin, registry);
    loaded = LoadWorld(args.world_file, load, *registry);
  } catch (const Error& e) {
    if (load_progress) load_progress->Abandon();
    return bad_input(e.what());
  } catch (const std::bad_alloc&) {
    // The machine's, not the world's: the summary says so all the same
    // (an earlier run's "ok" stayed in the folder).
    if (load_progress) load_progress->Abandon();
    return bad_input(
        "out of memory while loading the world (the machine, a ulimit or --max-memory gave no "
        "more; README, \"A world that does not fit\")");
  } catch (const std::exception& e) {
    if (load_progress) load_progress->Abandon();
    const std::string what = e.what();
    // oneTBB's worker threads: "pthread_create has failed".
    return bad_input(what.find("pthread_create") != std::string::npos
                         ? "cannot start the world's worker threads (" + what +
                               "): the system gave this process no more threads, or no room "
                               "for their stacks: see `ulimit -u` and `ulimit -v`"
                         : "while loading the world: " + what);
  }
  try {
    load.check_stop();  // a signal at the end of the load
  } catch (const Error& e) {
    if (load_progress) load_progress->Abandon();
    return bad_input(e.what());
  }
  if (load_progress) {
    load_progress->Loaded();
    loaded.world->set_start_progress(
        [&load_progress](const std::string& stage) { load_progress->Starting(stage); });
  }
  options.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  for (const std::string& warning : loaded.warnings)
    std::cerr << "warning: " << swarmsim::ValidUtf8(warning) << "\n";
  // --max-memory 1M on 50 robots ran at 54 MiB without a word.
  // (Not with --quiet: a sweep's runs, given a share of memory whatever their size.)
  if (!args.max_memory.empty() && loaded.world->robot_count() < kForecastMinRobots && !args.quiet)
    std::cerr << "note: --max-memory " << args.max_memory
              << " is not applied: worlds of fewer than " << GroupThousands(kForecastMinRobots)
              << " robots are not checked (this one has " << loaded.world->robot_count() << ")\n";
  // The memory check's switch: a value that is neither off nor on kept the
  // check on without a word, and off dropped --max-memory's cap silently.
  if (const char* check = std::getenv("SWARMSIM_MEMORY_CHECK");
      check != nullptr && check[0] != '\0' && !args.quiet) {
    if (IsOffValue(check) && !args.max_memory.empty())
      std::cerr << "note: --max-memory " << args.max_memory << " is not applied: "
                << "SWARMSIM_MEMORY_CHECK=" << ValidUtf8(check) << " turns the memory check off\n";
    else if (!IsOffValue(check) && !IsOnValue(check))
      std::cerr << "warning: SWARMSIM_MEMORY_CHECK='" << ValidUtf8(check)
                << "' is neither 0, off, false, no nor 1, on, true, yes: the memory check stays "
                   "on\n";
  }
  if (const int cores = TaskScheduler::HardwareThreads(); loaded.world->threads() > cores)
    std::cerr << "note: " << loaded.world->threads() << " threads on " << cores
              << " hardware threads: the steps wait for threads that cannot run at once, so "
                 "the run is slower than with --threads "
              << cores << " (the results are the same for any thread count)\n";
  std::string length_error;
  const std::optional<int64_t> steps = RunLength(args, loaded, &length_error);
  if (!steps) return bad_input(length_error);
  options.steps = *steps;
  options.print_hash = args.hash;
  options.state_hash = false;  // only where it is seen: --hash, summary.json (--out)
  options.quiet = args.quiet;
  // Snapshots and video: the recorder module, checked before the run starts.
  std::string recorder_error;
  const std::optional<ViewRecorderSettings> recording = RecorderSettingsOf(args, &recorder_error);
  if (!recorder_error.empty()) return bad_input(recorder_error);
  if (recording && !recording->video.empty()) {
    std::string extension = recording->video.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension != ".mp4")
      std::cerr << "note: --video " << swarmsim::ValidUtf8(recording->video.string())
                << ": the video is H.264 in an MP4 container whatever the file is called "
                   "(name it .mp4 for players that go by the name)\n";
  }
  // A snapshot holds no recording, video or pictures to go on with: refused
  // before the run, naming the option (the module's refusal came after it).
  if (!args.save_state.empty() || !args.load_state.empty()) {
    std::string with;
    if (recording)
      with = !recording->video.empty() ? "--video" : "--snapshot-every";
    else if (args.record || args.view)
      with = args.view ? "--view" : "--record";
    if (!with.empty())
      return bad_input(std::string(args.load_state.empty() ? "--save-state" : "--load-state") +
                       ": not with " + with +
                       ": a snapshot holds no recording, video or pictures to go on with; "
                       "record the run without saving its state, or save it without recording");
  }
  // An --out folder an earlier run wrote to: its files go before this run
  // writes any (else old snapshots and video sit beside new metrics).
  if (options.out_dir)
    if (const std::string note = RemoveEarlierOutputs(*options.out_dir); !note.empty())
      std::cerr << "note: " << swarmsim::ValidUtf8(note) << "\n";
  ViewRecorder* recorder = nullptr;
  if (recording) {
    const ViewRecorderDescriptor* view_recorder = loaded.world->registry().view_recorder();
    if (view_recorder == nullptr)
      return bad_input("this build of swarmsim records no snapshots or video");
    try {
      if (options.out_dir) CreateOutputFolder(*options.out_dir);  // for DIR/video.mp4
      recorder = view_recorder->add(loaded.world.get(), *recording);
    } catch (const Error& e) {
      return bad_input(e.what());
    }
    for (const std::string& note : recorder->notes())
      std::cerr << "note: " << swarmsim::ValidUtf8(note) << "\n";
    options.progress_note = [recorder] { return recorder->ProgressNote(); };
  }
  // The recording (swarm/record): --record or the world's record: setting.
  record::RunRecorder* run_recorder = nullptr;
  const bool snapshots = !args.save_state.empty() || !args.load_state.empty();
  if (snapshots && loaded.record_every > 0 && options.out_dir)
    std::cerr << "note: the world's record: setting is not followed with "
              << (args.load_state.empty() ? "--save-state" : "--load-state")
              << " (a snapshot holds no recording to go on with): no recording.swrec\n";
  if (args.record || args.view || (loaded.record_every > 0 && !snapshots)) {
    if (!options.out_dir) {
      if (args.record || args.view)
        return bad_input(std::string(args.view ? "--view" : "--record") +
                         " writes DIR/recording.swrec: pass --out DIR as well");
      std::cerr << "note: the world's record: setting writes DIR/recording.swrec: pass --out DIR "
                   "to record this run\n";
    } else {
      record::RecordSettings settings;
      settings.out_dir = *options.out_dir;
      settings.every = std::max<int64_t>(1, loaded.record_every);
      settings.world_file = args.world_file;
      settings.steps_planned = options.steps;
      settings.metric_names = loaded.metric_names;
      try {
        CreateOutputFolder(*options.out_dir);
        run_recorder = record::AddRecorder(loaded.world.get(), settings);
      } catch (const Error& e) {
        return bad_input(e.what());
      }
    }
  }
  // A run the watchdog ends (it exits from its own thread, the world's
  // stuck in a step) closes the video and the recording too, before its
  // summary.json: the video's last second was lost (20 of 36 frames in the
  // file, the summary saying 36), and record-info says how the run ended.
  // The video's recorder is touched by the world's thread only in the
  // record phase (Capture), which does not wait on anything that can stick.
  if (recorder != nullptr || run_recorder != nullptr)
    options.on_stuck_end = [recorder, run_recorder](const RunResult& stuck) {
      if (recorder != nullptr) {
        try {
          recorder->Finish();
        } catch (const Error&) {  // the run's own error is the one to tell
        }
      }
      if (run_recorder != nullptr)
        run_recorder->Finish(stuck.steps, stuck.signal != 0 ? "interrupted" : "error", stuck.error);
    };
  // --view: the page follows the recording while the run writes it.
  std::unique_ptr<viewer::Server> view_server;
  if (args.view && run_recorder != nullptr) {
    view_server = std::make_unique<viewer::Server>(*options.out_dir);
    if (const int code = BindViewServer(args.view_host, args.view_port, view_server.get()))
      return code;
    try {
      view_server->Start();
    } catch (const Error& e) {  // no thread to serve on
      return bad_input(e.what());
    }
  }
  // The process ends without returning here: the folder's lock file stayed
  // (the next run took it over, but it looked like a run still writing).
  if (out_lock) options.on_stuck_exit = [&out_lock] { out_lock->Release(); };
  // Snapshots: checked (and a state loaded) before the run starts.
  if (!args.save_state.empty() || !args.load_state.empty()) {
    const std::string why = loaded.world->SnapshotRefusal();
    // The advice says Python; this program runs no Python controller.
    if (!why.empty())
      return bad_input(std::string(args.load_state.empty() ? "--save-state" : "--load-state") +
                       ": " + why +
                       " (swarmsim run saves worlds whose robots run no script or controller; "
                       "a world driven from Python saves with World.snapshot(), README "
                       "\"Snapshots, reset and pickling\")");
  }
  if (!args.load_state.empty()) {
    // A regular file only (a folder threw from the read; a device or a pipe
    // never ended: /dev/zero filled memory).
    std::string why;
    const std::unique_ptr<RegularFile> file = RegularFile::Open(args.load_state, &why);
    const int64_t size = file ? file->CurrentSize() : -1;
    std::string bytes(std::max<int64_t>(size, 0), '\0');
    if (!file || size < 0 || !file->ReadAt(0, bytes.data(), bytes.size(), &why))
      return bad_input("--load-state: cannot read '" + args.load_state + "'" +
                       (why.empty() ? "" : ": " + why));
    try {
      loaded.world->RestoreState(bytes);
    } catch (const Error& e) {
      return bad_input("--load-state " + args.load_state + ": " + e.what());
    }
    // The state carries its random streams: another seed would be ignored.
    if (args.seed && *args.seed != loaded.world->settings().seed)
      return bad_input("--seed " + std::to_string(*args.seed) + ": the run --load-state " +
                       args.load_state + " resumes goes on with its own seed (" +
                       std::to_string(loaded.world->settings().seed) +
                       "); leave --seed out, or give that one");
    options.resumed_from = args.load_state;
  }
  if (!args.save_state.empty()) {
    options.save_state = args.save_state;
    options.save_state_at = args.save_state_at;
    const int64_t first = loaded.world->step_count();
    if (args.save_state_at >= 0 &&
        (args.save_state_at < first || args.save_state_at > first + options.steps))
      return bad_input("--save-state-at " + std::to_string(args.save_state_at) +
                       ": the run goes from step " + std::to_string(first) + " to " +
                       std::to_string(first + options.steps));
  }
  // Nothing runs this world again: its end need not free every Lua object
  // (--view serves the recording's files, not the world).
  loaded.world->set_process_ends_after_stop(true);
  // For the same reason, the world itself is left to the system when this
  // function returns, stopped first (its scripts' and native controllers'
  // cleanups run, as the destructor would run them): freeing a million
  // robots' rows and settings block by block took seconds of a large run's
  // end. Not under ASan (its leak check).
  struct LeaveWorld {
    std::unique_ptr<World>* world;
    ~LeaveWorld() {
      if (kAddressSanitizer || *world == nullptr) return;
      try {
        (*world)->Stop();
      } catch (...) {
        // A failing sysCall_cleanup: swallowed, as the destructor does.
      }
      (void)world->release();
    }
  } leave_world{&loaded.world};
  const RunResult result = RunWorld(loaded.world.get(), options, std::cout, std::cerr);
  // summary.json is written: its word is final. A stop signal from now on
  // is noted and changes nothing (the run is complete, the exit status is
  // the summary's); the signals stay caught until the program exits, so
  // that one cannot kill it halfway through closing the recording.
  if (run_recorder != nullptr)
    run_recorder->Finish(result.steps,
                         result.ok ? "ok" : (result.signal != 0 ? "interrupted" : "error"),
                         result.ok ? "" : result.error);
  if (view_server && result.signal == 0) {
    // The run's error now, not only after the serving (it was never printed).
    if (!result.ok) std::cerr << "error: " << swarmsim::ValidUtf8(result.error) << "\n";
    // The run is over, the page stays: serve until Ctrl-C, SIGTERM or SIGHUP,
    // which end the serving and leave the run's exit status as its summary
    // says (the signals stay caught: StopSignals notes them).
    std::cout << "swarmsim run: the run ended; still serving " << view_server->Address()
              << " (Ctrl-C to stop)" << std::endl;
    // (Polled: the signal may be delivered to a server thread, not this one.)
    while (StopSignals::Received() == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    view_server.reset();
    return result.ok ? 0 : kExitRunError;
  }
  if (recorder != nullptr) {
    // The video's end, also without --out (with it, the run's outputs did it).
    try {
      recorder->Finish();
    } catch (const Error& e) {
      if (result.ok) {
        std::cerr << "error: " << swarmsim::ValidUtf8(e.what()) << "\n";
        return kExitRunError;
      }
    }
    if (!args.quiet && args.video) std::cout << "video           " << recorder->VideoLine() << "\n";
  }
  if (!result.ok) {
    std::cerr << "error: " << swarmsim::ValidUtf8(result.error) << "\n";
    // Only when there is something to find (a disk full from the start: nothing).
    if (options.out_dir && std::filesystem::exists(*options.out_dir / "summary.json"))
      std::cerr << swarmsim::ValidUtf8(OutputsOfFinishedSteps(result.steps, *options.out_dir))
                << "\n";
    // The shell's convention for a run ended by a signal: 128 + its number.
    return result.signal != 0 ? 128 + result.signal : kExitRunError;
  }
  return 0;
}

}  // namespace swarmsim::cli
