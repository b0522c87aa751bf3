#include "swarm/bench/scaling.h"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>
#include <thread>

#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/regular_file.h"
#include "framework/utf8.h"

namespace swarmsim {
namespace {

struct Point {
  std::string kind;       // "robots=N" (threads) or "sweep" (jobs)
  int workers = 0;        // threads or jobs
  double throughput = 0;  // robot-ticks/s or runs/min
  double speedup = 0;
};

int Cores() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

int RunQuiet(const std::vector<std::string>& args) {
  fflush(nullptr);  // or the child's freopen would write our pending output again
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (!freopen("/dev/null", "w", stdout)) _exit(126);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// Step 1's rows: robot-ticks/s per robots x threads from the bench CSV, with
// the speed-up over one thread at the same robot count.
std::vector<Point> ReadThreadPoints(const std::string& bench_csv) {
  std::vector<Point> points;
  std::ifstream f(bench_csv);
  std::string line;
  std::getline(f, line);  // header
  std::map<int, double> one_thread;
  while (std::getline(f, line)) {
    std::vector<std::string> c;
    std::istringstream s(line);
    for (std::string field; std::getline(s, field, ',');) c.push_back(field);
    if (c.size() < 6 || c[0] != "diffusion") continue;
    Point p{"robots=" + c[1], std::stoi(c[2]), std::stod(c[5]), 0};
    if (p.workers == 1) one_thread[std::stoi(c[1])] = p.throughput;
    const auto base = one_thread.find(std::stoi(c[1]));
    p.speedup = base != one_thread.end() && base->second > 0 ? p.throughput / base->second : 0;
    points.push_back(p);
  }
  return points;
}

// Step 2: the same sweep at each --jobs, each into a fresh database in
// `scratch`; a row per jobs count to `out` and `points`. False when a sweep failed.
bool MeasureSweeps(const ScalingOptions& o, const std::filesystem::path& scratch,
                   std::vector<Point>* points, std::ostream& out, std::ostream& err) {
  out << "\n== sweep throughput: " << o.sweep_runs << " runs of " << o.bench.world << " ("
      << o.sweep_robots << " robots, " << o.sweep_steps << " steps, 1 thread each)\n"
      << std::setw(6) << "jobs" << std::setw(10) << "wall s" << std::setw(12) << "runs/min"
      << std::setw(10) << "speed-up"
      << "\n";
  out << std::flush;
  double base_rate = 0;
  bool ok = true;
  for (int jobs : o.jobs) {
    const std::string db = (scratch / ("sweep-" + std::to_string(jobs) + ".db")).string();
    const auto start = std::chrono::steady_clock::now();
    const int code =
        RunQuiet({o.bench.self_exe, "sweep", o.bench.world, "--param",
                  "robots=" + std::to_string(o.sweep_robots), "--seeds",
                  std::to_string(o.sweep_runs), "--steps", std::to_string(o.sweep_steps), "--jobs",
                  std::to_string(jobs), "--quiet", "--db", db});
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (code != 0) {
      err << "bench: sweep with --jobs " << jobs << " failed (exit " << code << ")\n";
      ok = false;
      continue;
    }
    const double rate = 60.0 * o.sweep_runs / wall;
    if (jobs == o.jobs.front()) base_rate = rate / jobs;
    Point p{"sweep", jobs, rate, base_rate > 0 ? rate / base_rate : 0};
    out << std::setw(6) << jobs << std::setw(10) << std::fixed << std::setprecision(2) << wall
        << std::setw(12) << std::setprecision(1) << rate << std::setw(10) << std::setprecision(2)
        << p.speedup << "\n"
        << std::defaultfloat << std::flush;
    points->push_back(p);
  }
  return ok;
}

// Step 4: the speed-up plot, one line per series beside the ideal, drawn by
// gnuplot into `plot`. False (and a message) when gnuplot fails or is missing.
bool PlotSpeedup(const std::map<std::string, std::vector<Point>>& series, int max_workers,
                 int cores, const std::string& plot, std::ostream& out, std::ostream& err) {
  std::ostringstream script;
  script << "set terminal pngcairo size 900,600 enhanced font 'sans,11'\n"
         << "set output '" << plot << "'\n"
         << "set title 'swarmsim scaling on " << cores << " cores' noenhanced\n"
         << "set xlabel 'threads (simulation) or jobs (sweep)'\nset ylabel 'speed-up'\n"
         << "set grid\nset key left top noenhanced\nset xrange [0.8:" << max_workers + 0.2
         << "]\nset yrange [0:" << max_workers + 0.5 << "]\nset xtics 1\n";
  std::vector<std::string> plots{"x with lines dt 2 lc rgb 'gray40' title 'ideal'"};
  int block = 0;
  for (const auto& [kind, ps] : series) {
    script << "$d" << block << " << EOD\n";
    for (const Point& p : ps) script << p.workers << " " << p.speedup << "\n";
    script << "EOD\n";
    plots.push_back("$d" + std::to_string(block) + " using 1:2 with linespoints lw 2 pt 7 title '" +
                    (kind == "sweep" ? "sweep (runs/min)" : kind + " (robot-ticks/s)") + "'");
    ++block;
  }
  script << "plot ";
  for (size_t i = 0; i < plots.size(); ++i) script << (i ? ", " : "") << plots[i];
  script << "\n";
  if (!RunGnuplot(script.str(), err)) return false;
  out << "plot: " << plot << "\n";
  return true;
}

}  // namespace

int RunScalingBench(ScalingOptions o, std::ostream& out, std::ostream& err) {
  // The world (default filled in, `robots` parameter) and the outputs are
  // checked before any output (a folder that is not there was found after
  // every measurement, which were lost).
  PrepareBench(&o.bench);
  CheckScalingOutputs(o.csv, o.plot);
  const int cores = Cores();
  if (!o.threads_given) {
    o.bench.threads.clear();
    for (int t = 1; t <= cores; ++t) o.bench.threads.push_back(t);
  }
  if (o.jobs.empty())
    for (int j = 1; j <= cores; ++j) o.jobs.push_back(j);
  const std::filesystem::path scratch =
      std::filesystem::temp_directory_path() / ("swarmsim-scaling-" + std::to_string(getpid()));
  std::filesystem::create_directories(scratch);

  // 1. Robot-ticks/s over robots x threads: the ordinary bench, one process per row.
  BenchOptions bench = o.bench;
  bench.csv = (scratch / "bench.csv").string();
  out << "== robot-ticks/s over robots x threads (" << cores << " cores)\n";
  const int bench_code = RunBench(bench, out, err);
  std::vector<Point> points = ReadThreadPoints(*bench.csv);

  // 2. Sweep throughput: the same sweep at --jobs 1 .. cores, each into a fresh database.
  bool ok = bench_code == 0;
  ok = MeasureSweeps(o, scratch, &points, out, err) && ok;
  std::filesystem::remove_all(scratch);

  // 3. The speed-up table and the CSV.
  out << "\n== speed-up (throughput / throughput on 1 thread or job)\n";
  std::ofstream csv(o.csv);
  if (!csv) throw Error(CannotWrite(o.csv));
  csv << "series,workers,throughput,unit,speedup\n";
  std::map<std::string, std::vector<Point>> series;
  for (const Point& p : points) {
    series[p.kind].push_back(p);
    csv << p.kind << ',' << p.workers << ',' << std::setprecision(10) << p.throughput << ','
        << (p.kind == "sweep" ? "runs/min" : "robot-ticks/s") << ',' << p.speedup << "\n";
    out << std::setw(14) << p.kind << std::setw(4) << p.workers << std::setw(8)
        << std::setprecision(3) << p.speedup << "x\n";
  }
  out << "csv: " << o.csv << "\n";

  // 4. The plot.
  int max_workers = 1;
  for (const Point& p : points) max_workers = std::max(max_workers, p.workers);
  ok = PlotSpeedup(series, max_workers, cores, o.plot, out, err) && ok;
  return ok ? 0 : 1;
}

bool RunGnuplot(const std::string& script, std::ostream& err) {
  // gnuplot's standard output is not ours: when it cannot open its output
  // file it writes the PNG there (35 KB of binary in the table's stream).
  // Its messages go to our standard error.
  std::fflush(nullptr);
  FILE* gp = popen("gnuplot >/dev/null", "w");
  if (gp) fwrite(script.data(), 1, script.size(), gp);
  const int status = gp ? pclose(gp) : -1;
  if (status != 0) {
    err << "bench: gnuplot failed (its message above) or is missing (install gnuplot-nox); "
           "no plot\n";
    return false;
  }
  return true;
}

void CheckScalingOutputs(const std::string& csv, const std::string& plot) {
  if (SameFile(csv, plot))
    throw Error("bench: --csv and --plot name one file, '" + ValidUtf8(csv) + "': name two");
  CheckBenchOutput(csv, "--csv", BenchOutput::kCsv);
  CheckBenchOutput(plot, "--plot", BenchOutput::kPng);
}

}  // namespace swarmsim
