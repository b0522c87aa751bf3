#include "swarm/bench/robot_scaling.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "framework/error.h"
#include "framework/output_file.h"
#include "swarm/bench/bench.h"
#include "swarm/bench/scaling.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

// The default configurations: name, world in the repository.
constexpr std::pair<const char*, const char*> kConfigs[] = {
    {"lua", "worlds/diffusion.yaml"},
    {"cpp", "worlds/diffusion_native.yaml"},
    {"planar-lua", "worlds/diffusion_planar.yaml"},
    {"planar-cpp", "bench/worlds/diffusion_planar_native.yaml"},
};

constexpr double kTicksPerRow = 2e6;
constexpr int64_t kMinSteps = 3, kMaxSteps = 1000;

// One measured row, with what the table derives from the child's.
struct ScalingRow {
  std::string config;
  BenchRow bench;
  double us_other = 0;  // wall per tick minus sense, control, physics: actuate, record, delivery
  double us_total = 0;  // wall time per robot-tick
  double ratio = 1;     // us_total over the config's first robot count (same threads)
};

constexpr const char* kCsvHeader =
    "config,world,robots,threads,steps,robot_ticks_per_s,us_sense,us_control,us_physics,"
    "us_other,us_total,cost_ratio,startup_s,peak_rss_mb,kb_per_robot";

std::string CsvRow(const ScalingRow& r, const std::string& world) {
  const BenchRow& b = r.bench;
  std::ostringstream s;
  s << std::setprecision(8) << r.config << ',' << world << ',' << b.robots << ',' << b.threads
    << ',' << b.steps << ',' << b.robot_ticks_per_s << ',' << b.us_per_tick[0] << ','
    << b.us_per_tick[1] << ',' << b.us_per_tick[3] << ',' << r.us_other << ',' << r.us_total << ','
    << r.ratio << ',' << b.startup_s << ',' << b.peak_rss_mb << ',' << b.kb_per_robot;
  return s.str();
}

void PrintHeader(std::ostream& out) {
  out << std::left << std::setw(12) << "config" << std::right << std::setw(9) << "robots"
      << std::setw(4) << "thr" << std::setw(6) << "steps" << std::setw(11) << "ticks/s"
      << std::setw(8) << "sense" << std::setw(8) << "control" << std::setw(8) << "physics"
      << std::setw(8) << "other" << std::setw(8) << "total" << std::setw(7) << "vs 1st"
      << std::setw(9) << "start s" << std::setw(10) << "peak MiB" << std::setw(9) << "KB/robot"
      << "\n"
      << std::string(12 + 9 + 4 + 6 + 11 + 8 * 5 + 7 + 9 + 10 + 9, '-') << "\n"
      << std::flush;
}

void PrintRow(const ScalingRow& r, std::ostream& out) {
  const BenchRow& b = r.bench;
  out << std::left << std::setw(12) << r.config << std::right << std::setw(9) << b.robots
      << std::setw(4) << b.threads << std::setw(6) << b.steps << std::setw(11) << std::fixed
      << std::setprecision(0) << b.robot_ticks_per_s << std::setprecision(2) << std::setw(8)
      << b.us_per_tick[0] << std::setw(8) << b.us_per_tick[1] << std::setw(8) << b.us_per_tick[3]
      << std::setw(8) << r.us_other << std::setw(8) << r.us_total << std::setw(7) << r.ratio
      << std::setw(9) << b.startup_s << std::setw(10) << std::setprecision(0) << b.peak_rss_mb
      << std::setw(9) << std::setprecision(1) << b.kb_per_robot << "\n"
      << std::defaultfloat << std::flush;
}

// gnuplot's single-quoted string: a quote is doubled.
std::string Quoted(const std::string& text) {
  std::string q = "'";
  for (char c : text) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

// "2 threads", "1 and 2 threads": the counts the rows were measured at.
std::string ThreadsText(const std::vector<ScalingRow>& rows) {
  std::set<int> counts;
  for (const ScalingRow& r : rows) counts.insert(r.bench.threads);
  std::string text;
  size_t i = 0;
  for (const int t : counts)
    text += (i++ == 0 ? "" : i == counts.size() ? " and " : ", ") + std::to_string(t);
  return text + (counts.size() == 1 && *counts.begin() == 1 ? " thread" : " threads");
}

// Two log-log panels: microseconds per robot-tick against robots (the total
// solid, each phase dashed in the configuration's colour), and start-up
// seconds against robots. False (and a message) when gnuplot fails or is missing.
bool Plot(const std::vector<ScalingRow>& rows, const RobotScalingOptions& o, std::ostream& out,
          std::ostream& err) {
  // Series: config (and threads, when more than one count was measured).
  std::map<std::string, std::vector<const ScalingRow*>> series;
  std::vector<std::string> order;
  for (const ScalingRow& r : rows) {
    std::string key = r.config;
    if (o.threads.size() > 1) key += ", " + std::to_string(r.bench.threads) + " thr";
    if (!series.contains(key)) order.push_back(key);
    series[key].push_back(&r);
  }
  std::ostringstream script;
  script << "set terminal pngcairo size 1200,640 enhanced font 'sans,10'\n"
         << "set output " << Quoted(o.plot) << "\n"
         << "set logscale xy\nset grid\nset key below horizontal maxcols 4 noenhanced\n"
         << "set format x '10^{%L}'\nset xlabel 'robots'\n"
         // The key below: a margin for it under the axis's label (two rows:
         // the configurations' colours, then the phases' dashes).
         << "set bmargin 8\n"
         << "set multiplot layout 1,2 title "
         << Quoted("swarmsim: cost per robot-tick over robot counts (" + ThreadsText(rows) + "; " +
                   (o.steps > 0 ? std::to_string(o.steps) + " measured steps a row"
                                : std::string("2 million robot-ticks over the robots, 3 to "
                                              "1,000 steps a row")) +
                   ")")
         << "\n";
  // One robot count: a range about it (gnuplot would warn of an empty one).
  int lowest = INT_MAX, highest = 0;
  for (const ScalingRow& r : rows)
    lowest = std::min(lowest, r.bench.robots), highest = std::max(highest, r.bench.robots);
  // The robots measured, and a little about them (a decade without data
  // stood at the left of the axis).
  if (!rows.empty())
    script << "set xrange [" << lowest / (lowest == highest ? 2.0 : 1.4) << ":"
           << highest * (lowest == highest ? 2.0 : 1.4) << "]\n";
  int block = 0;
  for (const std::string& key : order) {
    script << "$d" << block++ << " << EOD\n";
    for (const ScalingRow* r : series[key]) {
      const BenchRow& b = r->bench;
      // robots total sense control physics other startup
      script << b.robots << ' ' << r->us_total << ' ' << std::max(b.us_per_tick[0], 1e-3) << ' '
             << std::max(b.us_per_tick[1], 1e-3) << ' ' << std::max(b.us_per_tick[3], 1e-3) << ' '
             << std::max(r->us_other, 1e-3) << ' ' << std::max(b.startup_s, 1e-3) << "\n";
    }
    script << "EOD\n";
  }
  const char* phases[] = {"sense", "control", "physics", "other"};
  script << "set ylabel 'microseconds per robot-tick'\nplot ";
  for (int i = 0; i < block; ++i) {
    const std::string d = "$d" + std::to_string(i);
    const std::string colour = " lc " + std::to_string(i + 1);
    script << (i ? ", " : "") << d << " using 1:2 with linespoints lw 2 pt 7" << colour << " title "
           << Quoted(order[i] + " total");
    for (int p = 0; p < 4; ++p)
      script << ", " << d << " using 1:" << 3 + p << " with linespoints dt " << 2 + p << " lw 1 pt "
             << 1 + p << colour << " notitle";
  }
  // The phases' dashes, once (a key entry per configuration and phase,
  // twenty for four, ran over the axis's label).
  for (int p = 0; p < 4; ++p)
    script << ", NaN with linespoints dt " << 2 + p << " lw 1 pt " << 1 + p << " lc black title "
           << Quoted(phases[p]);
  // Start-up of one count and configuration: a range about it (as above).
  double first_startup = rows.empty() ? 0 : std::max(rows.front().bench.startup_s, 1e-3);
  bool one_startup = true;
  for (const ScalingRow& r : rows)
    one_startup = one_startup && std::max(r.bench.startup_s, 1e-3) == first_startup;
  script << "\n";
  if (!rows.empty() && one_startup)
    script << "set yrange [" << first_startup / 10 << ":" << first_startup * 10 << "]\n";
  script << "set ylabel 'start-up seconds (load to first step)'\nplot ";
  for (int i = 0; i < block; ++i)
    script << (i ? ", " : "") << "$d" << i << " using 1:7 with linespoints lw 2 pt 7 lc " << i + 1
           << " title " << Quoted(order[i]);
  script << "\nunset multiplot\n";
  std::fflush(nullptr);
  if (!RunGnuplot(script.str(), err)) return false;
  out << "plot: " << o.plot << "\n";
  return true;
}

}  // namespace

int64_t AutoScalingSteps(int robots) {
  const double steps = std::floor(kTicksPerRow / std::max(robots, 1));
  return std::clamp(static_cast<int64_t>(steps), kMinSteps, kMaxSteps);
}

int64_t AutoWarmupSteps(int64_t steps) { return std::clamp<int64_t>(steps / 10, 2, 20); }

std::vector<ScalingConfig> DefaultScalingConfigs() {
  std::vector<ScalingConfig> configs;
  for (const auto& [name, relative] : kConfigs) {
    const std::string world = FindInSourceTree(relative);
    if (world.empty())
      throw Error(std::string("bench: the ") + name + " configuration's world " + relative +
                  " was found neither beside the program nor in the current folder; pass "
                  "--world FILE");
    configs.push_back({name, world});
  }
  return configs;
}

std::vector<ScalingConfig> SelectScalingConfigs(const std::vector<std::string>& names) {
  std::vector<ScalingConfig> selected;
  for (const std::string& name : names) {
    const auto it = std::find_if(std::begin(kConfigs), std::end(kConfigs),
                                 [&](const auto& c) { return name == c.first; });
    if (it == std::end(kConfigs)) {
      std::string known;
      for (const auto& c : kConfigs) known += std::string(known.empty() ? "" : ", ") + c.first;
      throw Error("bench: unknown configuration '" + name + "' (known: " + known + ")");
    }
    const std::string world = FindInSourceTree(it->second);
    if (world.empty())
      throw Error(std::string("bench: the ") + name + " configuration's world " + it->second +
                  " was found neither beside the program nor in the current folder");
    selected.push_back({name, world});
  }
  return selected;
}

int RunRobotScalingBench(RobotScalingOptions o, std::ostream& out, std::ostream& err) {
  // Everything that can be checked is, before any output.
  if (o.configs.empty()) o.configs = DefaultScalingConfigs();
  for (ScalingConfig& c : o.configs) {
    BenchOptions check;
    check.world = c.world;
    PrepareBench(&check);
  }
  CheckScalingOutputs(o.csv, o.plot);
  if (o.threads.empty())
    o.threads = {static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))};
  std::ofstream csv(o.csv);
  if (!csv) throw Error(CannotWrite(o.csv));
  csv << kCsvHeader << "\n" << std::flush;

  out << "microseconds per robot-tick by phase (a tick = one robot for one control step); "
         "one process per row;\nsteps: "
      << (o.steps > 0 ? std::to_string(o.steps)
                      : std::string("2,000,000 robot-ticks over the robots, 3 to 1,000 a row"))
      << "; vs 1st: total over the configuration's first robot count; start s: load to first "
         "step\n";
  for (const ScalingConfig& c : o.configs) out << "  " << c.name << ": " << c.world << "\n";
  out << "\n";
  PrintHeader(out);
  // The rows in table order: (configuration, threads, robots).
  struct Cell {
    const ScalingConfig* config;
    int threads, robots;
    std::vector<ScalingRow> runs;  // one per round that measured it
  };
  std::vector<Cell> cells;
  for (const ScalingConfig& c : o.configs)
    for (int threads : o.threads)
      for (int robots : o.robots) cells.push_back({&c, threads, robots, {}});
  const int rounds = std::max(o.repeat, 1);
  bool ok = true;
  std::vector<ScalingRow> rows;
  // The row of a cell: its round of median total, its ratio to the
  // configuration's first count (same threads) as reported.
  double first_total = 0;
  const ScalingConfig* first_of = nullptr;
  int first_threads = 0;
  const auto report = [&](Cell& cell) {
    if (cell.runs.empty()) return;
    std::sort(cell.runs.begin(), cell.runs.end(),
              [](const ScalingRow& a, const ScalingRow& b) { return a.us_total < b.us_total; });
    ScalingRow row = cell.runs[(cell.runs.size() - 1) / 2];
    if (first_of != cell.config || first_threads != cell.threads) {
      first_of = cell.config;
      first_threads = cell.threads;
      first_total = row.us_total;
    }
    row.ratio = first_total > 0 ? row.us_total / first_total : 0;
    PrintRow(row, out);
    csv << CsvRow(row, cell.config->world) << "\n" << std::flush;
    rows.push_back(row);
  };
  std::set<std::string> warned;  // each world's load-time warnings said once
  for (int round = 1; round <= rounds; ++round) {
    for (Cell& cell : cells) {
      const ScalingConfig& c = *cell.config;
      BenchOptions bench;
      bench.world = c.world;
      bench.self_exe = o.self_exe;
      bench.steps = o.steps > 0 ? o.steps : AutoScalingSteps(cell.robots);
      bench.warmup_steps = o.warmup_steps >= 0 ? o.warmup_steps : AutoWarmupSteps(bench.steps);
      ScalingRow row;
      row.config = c.name;
      std::vector<std::string> warnings;
      const bool measured =
          MeasureInChild(bench, "diffusion", cell.robots, cell.threads, &row.bench, &warnings);
      SayNewWarnings(warnings, &warned, err);
      if (!measured) {
        err << "bench: " << c.name << " with " << cell.robots << " robots on " << cell.threads
            << (cell.threads == 1 ? " thread" : " threads") << " failed\n";
        ok = false;
        continue;
      }
      const BenchRow& b = row.bench;
      const double ticks = static_cast<double>(b.robots) * static_cast<double>(b.steps);
      row.us_total = ticks > 0 ? 1e6 * b.wall_s / ticks : 0;
      row.us_other =
          std::max(0.0, row.us_total - b.us_per_tick[0] - b.us_per_tick[1] - b.us_per_tick[3]);
      cell.runs.push_back(row);
      if (rounds == 1) {
        report(cell);  // as it comes
      } else {
        err << "bench: round " << round << " of " << rounds << ": " << c.name << ", " << cell.robots
            << " robots, " << cell.threads << " thr: " << std::fixed << std::setprecision(2)
            << row.us_total << " us per robot-tick\n"
            << std::defaultfloat << std::flush;
      }
    }
  }
  if (rounds > 1)
    for (Cell& cell : cells) report(cell);
  out << "csv: " << o.csv << "\n";
  if (!rows.empty()) ok = Plot(rows, o, out, err) && ok;
  return ok ? 0 : 1;
}

}  // namespace swarmsim
