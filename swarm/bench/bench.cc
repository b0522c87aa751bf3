#include "swarm/bench/bench.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>
#include <string_view>

#include "framework/display_path.h"
#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/registry.h"
#include "framework/regular_file.h"
#include "framework/utf8.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "swarm/run/runner.h"

namespace swarmsim {

namespace {

// A child's line after its CSV row: one of the world's load-time warnings.
constexpr std::string_view kWarningLine = "warning: ";

namespace fs = std::filesystem;

constexpr const char* kDefaultWorld = "worlds/diffusion.yaml";

// Where a world's `plugins: [NAME]` are looked for, as `swarmsim run` does:
// plugins/ beside this program.
std::vector<fs::path> BenchPluginDirectories() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  return {exe.parent_path() / "plugins", exe.parent_path().parent_path() / "lib/swarmsim/plugins"};
}

constexpr const char* kCsvHeader =
    "config,robots,threads,steps,wall_s,robot_ticks_per_s,us_sense,us_control,us_actuate,"
    "us_physics,us_record,peak_rss_mb,kb_per_robot,startup_s";

// The first lines of the CSV files bench writes (plain, --scaling-robots,
// --scaling): a file that starts with none of them is not bench's to
// overwrite.
constexpr std::string_view kBenchCsvHeaders[] = {
    kCsvHeader,
    "config,world,robots,threads,steps,robot_ticks_per_s,us_sense,us_control,us_physics,"
    "us_other,us_total,cost_ratio,startup_s,peak_rss_mb,kb_per_robot",
    "series,workers,throughput,unit,speedup"};

std::string ToCsv(const BenchRow& r) {
  std::ostringstream s;
  s << std::setprecision(8) << r.config << ',' << r.robots << ',' << r.threads << ',' << r.steps
    << ',' << r.wall_s << ',' << r.robot_ticks_per_s;
  for (double us : r.us_per_tick) s << ',' << us;
  s << ',' << r.peak_rss_mb << ',' << r.kb_per_robot << ',' << r.startup_s;
  return s.str();
}

bool FromCsv(const std::string& line, BenchRow* r) {
  std::istringstream s(line);
  std::string field;
  std::vector<std::string> f;
  while (std::getline(s, field, ',')) f.push_back(field);
  if (f.size() != 14) return false;
  try {
    r->config = f[0];
    r->robots = std::stoi(f[1]);
    r->threads = std::stoi(f[2]);
    r->steps = std::stoll(f[3]);
    r->wall_s = std::stod(f[4]);
    r->robot_ticks_per_s = std::stod(f[5]);
    for (int i = 0; i < 5; ++i) r->us_per_tick[i] = std::stod(f[6 + i]);
    r->peak_rss_mb = std::stod(f[11]);
    r->kb_per_robot = std::stod(f[12]);
    r->startup_s = std::stod(f[13]);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

// Runs `argv` and returns its standard output; the child's stderr passes through.
bool RunChild(const std::vector<std::string>& args, std::string* output, int* status) {
  int fds[2];
  if (pipe(fds) != 0) return false;
  const pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    close(fds[1]);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(fds[1]);
  char buf[4096];
  ssize_t n;
  while ((n = read(fds[0], buf, sizeof buf)) > 0) output->append(buf, static_cast<size_t>(n));
  close(fds[0]);
  waitpid(pid, status, 0);
  return true;
}

}  // namespace

int RunBenchChild(const BenchOptions& options, const std::string& config, int robots, int threads,
                  std::ostream& out) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  // "diffusion" (the whole world), or "<physics>-only": the world's
  // dynamics backend alone, through the bare loop it registered.
  const bool bare = config.ends_with("-only");
  const std::string physics = bare ? config.substr(0, config.size() - 5) : std::string();
  if (config != "diffusion" && (!bare || registry.FindBareLoop(physics) == nullptr))
    throw Error("unknown bench configuration '" + config + "'");
  LoadOptions load;
  load.overrides = {{"robots", std::to_string(robots)}};
  load.seed = 1;
  load.threads = threads;
  load.plugin_directories = BenchPluginDirectories();
  // Start-up: the world loaded (models copied, robots placed) and started
  // (engine built, Lua states made, sysCall_init run), up to its first step.
  const auto load_start = std::chrono::steady_clock::now();
  LoadedWorld loaded = LoadWorld(options.world, load, registry);
  World& world = *loaded.world;
  world.set_log_sink([](std::string_view) {});
  world.Start();
  const double startup_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
  // Warm-up through the full pipeline: scripts set the wheel commands.
  for (int64_t i = 0; i < options.warmup_steps; ++i) world.Step();

  BenchRow row;
  row.config = config;
  row.robots = world.robot_count();
  row.threads = bare ? 1 : world.threads();
  row.steps = options.steps;
  row.startup_s = startup_s;
  const double ticks = static_cast<double>(row.robots) * static_cast<double>(options.steps);
  if (config == "diffusion") {
    const PhaseTimes before = world.phase_times();
    const auto start = std::chrono::steady_clock::now();
    for (int64_t i = 0; i < options.steps; ++i) world.Step();
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (int p = 0; p < 5; ++p)
      row.us_per_tick[p] = 1e6 * (world.phase_times()[p] - before[p]) / ticks;
  } else {
    // The same bodies and wheel or joint commands through the engine alone.
    const WorldSettings& s = world.settings();
    row.wall_s = (*registry.FindBareLoop(physics))(world.scene(), s.time_step / s.physics_substeps,
                                                   s.physics_substeps,
                                                   static_cast<int>(options.steps), s.gravity);
    row.us_per_tick[static_cast<int>(Phase::kPhysics)] = 1e6 * row.wall_s / ticks;
  }
  row.robot_ticks_per_s = row.wall_s > 0 ? ticks / row.wall_s : 0;
  row.peak_rss_mb = PeakRssMb();
  row.kb_per_robot = row.robots > 0 ? row.peak_rss_mb * 1024.0 / row.robots : 0;
  out << ToCsv(row) << "\n";
  for (std::string warning : loaded.warnings) {  // one line each, as run prints them
    warning = ValidUtf8(warning);
    std::replace(warning.begin(), warning.end(), '\n', ' ');
    out << kWarningLine << warning << "\n";
  }
  return 0;
}

std::string FindInSourceTree(const std::string& relative) {
  // The source tree beside the program: build/swarmsim -> worlds/diffusion.yaml.
  std::error_code ec;
  const fs::path exe = fs::canonical("/proc/self/exe", ec);
  if (!ec) {
    const fs::path beside = exe.parent_path().parent_path() / relative;
    if (fs::is_regular_file(beside, ec)) return DisplayPath(beside);
  }
  // Else the current folder (a repository root).
  if (fs::is_regular_file(relative, ec)) return relative;
  return "";
}

std::string DefaultBenchWorld() { return FindInSourceTree(kDefaultWorld); }

std::string PrepareBench(BenchOptions* options) {
  // The world: the one given, else the diffusion world found beside the program.
  if (options->world.empty()) {
    options->world = DefaultBenchWorld();
    if (options->world.empty())
      throw Error(std::string("bench: no --world given and the default world ") + kDefaultWorld +
                  " was found neither beside the program nor in the current folder; pass "
                  "--world FILE");
  }
  std::error_code ec;
  if (!fs::is_regular_file(options->world, ec))
    throw Error("bench: world file '" + options->world + "' not found");

  // It must load with the robot count set through its `robots` parameter.
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  LoadOptions load;
  load.overrides = {{"robots", "1"}};
  load.plugin_directories = BenchPluginDirectories();
  // The bare-engine row of the world's backend, if it registered a bare
  // loop (kinematic has none: its row is the box2d one, as before).
  const auto bare_row = [&registry](const LoadedWorld& loaded) {
    const std::string& physics = loaded.world->settings().physics;
    return registry.FindBareLoop(physics) != nullptr ? physics + "-only" : "box2d-only";
  };
  try {
    return bare_row(LoadWorld(options->world, load, registry));
  } catch (const Error&) {
    // Tell a missing `robots` parameter from the file's own mistakes, which
    // loading it as written reports (and throws).
    LoadOptions as_is;
    as_is.plugin_directories = load.plugin_directories;
    const LoadedWorld as_written = LoadWorld(options->world, as_is, registry);
    if (!as_written.world->parameters().contains("robots"))
      throw Error("bench: world '" + options->world +
                  "' has no parameter 'robots'; bench sets the robot count through it "
                  "(declare parameters: {robots: N} and use count: $robots in its models entry)");
    // A world that loads as written but not with one robot (an arena sized
    // by the count, too small for its obstacles at one): the counts asked
    // for are measured; each one that does not load says why in its row.
    return bare_row(as_written);
  }
}

bool MeasureInChild(const BenchOptions& options, const std::string& config, int robots, int threads,
                    BenchRow* row, std::vector<std::string>* warnings) {
  const std::vector<std::string> args{options.self_exe,  "bench",
                                      "--child",         config,
                                      "--child-robots",  std::to_string(robots),
                                      "--child-threads", std::to_string(threads),
                                      "--child-warmup",  std::to_string(options.warmup_steps),
                                      "--steps",         std::to_string(options.steps),
                                      "--world",         options.world};
  std::string output;
  int status = 0;
  if (!(RunChild(args, &output, &status) && WIFEXITED(status) && WEXITSTATUS(status) == 0 &&
        FromCsv(output.substr(0, output.find('\n')), row)))
    return false;
  if (warnings != nullptr) {
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);)
      if (line.starts_with(kWarningLine)) warnings->push_back(line.substr(kWarningLine.size()));
  }
  return true;
}

void SayNewWarnings(const std::vector<std::string>& warnings, std::set<std::string>* said,
                    std::ostream& err) {
  for (const std::string& warning : warnings)
    if (said->insert(warning).second) err << "warning: " << warning << "\n" << std::flush;
}

void CheckBenchOutput(const std::string& path, const char* flag, BenchOutput kind) {
  const std::string named = std::string(flag) + " '" + ValidUtf8(path) + "'";
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::exists(status)) {
    if (const std::string why = NotAnOrdinaryFile(path); !why.empty())
      throw Error("bench " + named + ": " + why + ": name a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(std::string("bench ") + flag + ": " + CannotWrite(path));
    std::string first;
    if (kind == BenchOutput::kCsv) {
      std::getline(in, first);
      if (!first.empty() && first.back() == '\r') first.pop_back();
    } else {
      first.resize(8);
      in.read(first.data(), 8);
      first.resize(static_cast<size_t>(in.gcount()));
    }
    const bool empty = first.empty() && fs::file_size(path, ec) == 0;
    bool ours = false;
    if (kind == BenchOutput::kCsv)
      for (std::string_view header : kBenchCsvHeaders) ours = ours || first == header;
    else
      ours = first == std::string_view("\x89PNG\r\n\x1a\n", 8);
    if (!empty && !ours)
      throw Error("bench " + named + " is a file that is not " +
                  (kind == BenchOutput::kCsv ? "a CSV of bench's (its first line is not a bench "
                                               "header)"
                                             : "a PNG image") +
                  ": bench would write over it; name another file, or remove it first");
    // Writable as it is (opened without truncating it).
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw Error(std::string("bench ") + flag + ": " + CannotWrite(path));
    ::close(fd);
    return;
  }
  // A new file: made and removed, so that a missing or read-only folder is
  // said now, not after the measurements.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(std::string("bench ") + flag + ": " + CannotWrite(path));
  ::close(fd);
  ::unlink(path.c_str());
}

int RunBench(BenchOptions options, std::ostream& out, std::ostream& err) {
  // Everything that can be checked is, before the table's header.
  const std::string bare = PrepareBench(&options);
  if (options.csv) CheckBenchOutput(*options.csv, "--csv", BenchOutput::kCsv);
  std::vector<BenchRow> rows;
  std::unique_ptr<std::ofstream> csv;
  if (options.csv) {
    csv = std::make_unique<std::ofstream>(*options.csv);
    if (!*csv) throw Error(CannotWrite(*options.csv));
    *csv << kCsvHeader << "\n" << std::flush;
  }
  // The whole world's rows are named after its file (diffusion for the
  // default world), in the table and the CSV alike.
  const std::string world_label = fs::path(options.world).stem().string();
  const int width = std::max(12, static_cast<int>(world_label.size()) + 2);  // of the first column
  out << "world " << options.world << ", " << options.steps << " measured steps after "
      << options.warmup_steps << " warm-up steps; one process per row\n\n";
  out << std::left << std::setw(width) << "config" << std::right << std::setw(8) << "robots"
      << std::setw(8) << "threads" << std::setw(14) << "ticks/s" << std::setw(9) << "sense"
      << std::setw(9) << "control" << std::setw(9) << "actuate" << std::setw(9) << "physics"
      << std::setw(9) << "record" << std::setw(10) << "peak MiB" << std::setw(9) << "KB/robot"
      << "\n"
      << std::string(static_cast<size_t>(width) + 8 + 8 + 14 + 9 * 5 + 10 + 9, '-') << "\n"
      << std::flush;
  std::set<std::string> warned;  // each of the world's warnings said once
  auto measure = [&](const std::string& config, int robots, int threads) {
    BenchRow row;
    const std::string label = config == "diffusion" ? world_label : config;
    std::vector<std::string> warnings;
    const bool measured = MeasureInChild(options, config, robots, threads, &row, &warnings);
    SayNewWarnings(warnings, &warned, err);
    if (!measured) {
      err << "bench: " << label << " with " << robots << (robots == 1 ? " robot" : " robots")
          << " on " << threads << (threads == 1 ? " thread" : " threads") << " failed\n";
      return false;
    }
    row.config = label;
    out << std::left << std::setw(width) << row.config << std::right << std::setw(8) << row.robots
        << std::setw(8) << row.threads << std::setw(14) << std::fixed << std::setprecision(0)
        << row.robot_ticks_per_s << std::setprecision(3);
    for (double us : row.us_per_tick) out << std::setw(9) << us;
    out << std::setw(10) << std::setprecision(1) << row.peak_rss_mb << std::setw(9)
        << row.kb_per_robot << "\n"
        << std::defaultfloat << std::flush;
    if (csv) *csv << ToCsv(row) << "\n" << std::flush;
    rows.push_back(row);
    return true;
  };
  bool ok = true;
  // The bare-engine row (`bare`) matches the world's backend: ode-only for an ODE world.
  for (int robots : options.robots) {
    for (int threads : options.threads) ok = measure("diffusion", robots, threads) && ok;
    ok = measure(bare, robots, 1) && ok;
  }
  out << "\nphase columns: microseconds per robot-tick (a tick = one robot for one control step)\n";
  return ok ? 0 : 1;
}

}  // namespace swarmsim
