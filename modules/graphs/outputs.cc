// A run's graph files: graphs/<path>.csv for every graph, and graphs/<path>.png
// drawn by one gnuplot process for all of them (up to kMaxPngs).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "framework/csv.h"
#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/scheduler.h"
#include "framework/world.h"
#include "modules/graphs/module.h"

extern char** environ;

namespace swarmsim::graphs {

namespace fs = std::filesystem;

namespace {

// Appends the shortest text that reads back as the same double; "nan", "inf".
void AppendNumber(std::string* out, double v) {
  if (std::isnan(v)) {
    out->append("nan");
    return;
  }
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out->append(buf, r.ptr);
}

// A series as CSV: a header row, then time and the streams, one row per sample.
std::string CsvText(const Series& s) {
  std::string text = "time";
  for (const StreamSpec& stream : s.settings.streams) {
    text += ',';
    text += CsvField(stream.name);
  }
  text += '\n';
  text.reserve(text.size() + s.count * s.width() * 20);
  for (size_t i = 0; i < s.count; ++i) {
    const double* v = s.sample(i);
    for (size_t c = 0; c < s.width(); ++c) {
      if (c) text += ',';
      AppendNumber(&text, v[c]);
    }
    text += '\n';
  }
  return text;
}

std::string GnuplotQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

std::string Num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

// The finite values' range of column c, or false if it has none.
bool RangeOf(const Series& s, size_t c, double* lo, double* hi) {
  *lo = INFINITY;
  *hi = -INFINITY;
  for (size_t i = 0; i < s.count; ++i) {
    const double v = s.sample(i)[c];
    if (!std::isfinite(v)) continue;
    *lo = std::min(*lo, v);
    *hi = std::max(*hi, v);
  }
  return *lo <= *hi;
}

// "[lo:hi]" with a margin (a flat line gets one of its own).
std::string AxisRange(double lo, double hi, double margin) {
  double pad = (hi - lo) * margin;
  if (!(pad > 0)) pad = std::max(1e-3, std::abs(hi) * 0.05);
  std::string range(1, '[');
  range.append(Num(lo - pad)).append(1, ':').append(Num(hi + pad)).append(1, ']');
  return range;
}

std::string Label(const StreamSpec& s) {
  const std::string& unit = s.unit;
  return unit.empty() ? s.name : s.name + " (" + unit + ")";
}

// One graph's gnuplot commands (ranges computed here: gnuplot stops the
// whole script at "all points undefined", so it never autoscales).
void PlotCommands(const Series& s, const fs::path& csv, const fs::path& png, std::ostream& gp) {
  const GraphRow& g = s.settings;
  const std::string data = GnuplotQuote(csv.string()) + " skip 1";
  gp << "reset\nset datafile separator comma\nset grid\nset output " << GnuplotQuote(png.string())
     << "\nset title " << GnuplotQuote(g.title.empty() ? s.path : g.title) << "\n";
  const auto no_data = [&] {
    gp << "set label 1 'no data' at graph 0.5, 0.5 center\nset xrange [0:1]\nset yrange [0:1]\n"
          "plot 2 notitle\nunset output\n";
  };
  const size_t n = g.streams.size();
  double lo[4], hi[4];
  if (g.kind == GraphKind::kTime) {
    // The streams with data; two units get an axis each (y and y2).
    std::vector<size_t> plotted;
    std::vector<std::string> units;
    double ylo[2] = {INFINITY, INFINITY}, yhi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
      double a, b;
      if (!RangeOf(s, i + 1, &a, &b)) continue;
      plotted.push_back(i);
      if (std::find(units.begin(), units.end(), g.streams[i].unit) == units.end())
        units.push_back(g.streams[i].unit);
    }
    if (plotted.empty() || !RangeOf(s, 0, &lo[0], &hi[0])) return no_data();
    const bool two_axes = units.size() == 2;
    const auto axis = [&](size_t i) { return two_axes && g.streams[i].unit == units[1] ? 1 : 0; };
    for (size_t i : plotted) {
      double a, b;
      RangeOf(s, i + 1, &a, &b);
      ylo[axis(i)] = std::min(ylo[axis(i)], a);
      yhi[axis(i)] = std::max(yhi[axis(i)], b);
    }
    gp << "set xlabel 'time (s)'\nset ylabel " << GnuplotQuote(units.size() == 1 ? units[0] : "")
       << "\nset xrange " << AxisRange(lo[0], hi[0], 0) << "\nset yrange "
       << AxisRange(ylo[0], yhi[0], 0.05) << "\n";
    if (two_axes)
      gp << "set ylabel " << GnuplotQuote(units[0]) << "\nset y2label " << GnuplotQuote(units[1])
         << "\nset y2range " << AxisRange(ylo[1], yhi[1], 0.05)
         << "\nset ytics nomirror\nset y2tics\n";
    gp << "set key outside right top\nplot ";
    for (size_t k = 0; k < plotted.size(); ++k)
      gp << (k ? ", \\\n     " : "") << data << " using 1:" << plotted[k] + 2
         << (axis(plotted[k]) ? " axes x1y2" : "") << " with lines lw 1.5 title "
         << GnuplotQuote(g.streams[plotted[k]].name +
                         (two_axes ? " (" + g.streams[plotted[k]].unit + ")" : ""));
    gp << "\nunset output\n";
    return;
  }
  for (size_t c = 1; c <= n; ++c)
    if (!RangeOf(s, c, &lo[c], &hi[c])) return no_data();
  const bool same_units = std::all_of(g.streams.begin(), g.streams.end(),
                                      [&](const auto& x) { return x.unit == g.streams[0].unit; });
  const char* axes[3] = {"x", "y", "z"};
  for (size_t c = 1; c <= n; ++c)
    gp << "set " << axes[c - 1] << "label " << GnuplotQuote(Label(g.streams[c - 1]))
       << (c == 3 ? " rotate parallel" : "") << "\nset " << axes[c - 1] << "range "
       << AxisRange(lo[c], hi[c], 0.05) << "\n";
  gp << "set key top right\n";
  if (g.kind == GraphKind::kXy) {
    // Equal scales for a path in the plane, unless that squeezes it flat.
    const double ratio = (hi[2] - lo[2]) / (hi[1] - lo[1]);
    if (same_units && ratio > 1.0 / 3 && ratio < 3) gp << "set size ratio -1\n";
    gp << "plot " << data << " using 2:3 with lines lw 1.5 notitle, \\\n     " << data
       << " every ::0::0 using 2:3 with points pt 7 ps 1.5 title 'start'\nunset output\n";
  } else {
    if (same_units) gp << "set view equal xy\n";
    gp << "set ticslevel 0\nset border 4095\nsplot " << data
       << " using 2:3:4 with lines lw 1.5 notitle, \\\n     " << data
       << " every ::0::0 using 2:3:4 with points pt 7 ps 1.5 title 'start'\n"
       << "unset output\n";
  }
}

// "gnuplot not found" in the words the user needs.
constexpr const char* kNoGnuplot = "gnuplot not found; install gnuplot-nox (tools/setup.sh)";

// Starts `gnuplot script` with its messages into `log`. Returns "" and sets
// *pid, or says why it could not.
std::string StartGnuplot(const fs::path& script, const fs::path& log, pid_t* pid) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::string script_arg = script.string();
  char gnuplot[] = "gnuplot";
  char* argv[] = {gnuplot, script_arg.data(), nullptr};
  const int error = posix_spawnp(pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error == ENOENT) return kNoGnuplot;
  if (error != 0) return std::string("cannot run gnuplot: ") + std::strerror(error);
  return "";
}

// Waits for a gnuplot StartGnuplot started: "" if it succeeded, else why not.
std::string FinishGnuplot(pid_t pid, const fs::path& log) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return kNoGnuplot;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  // Its first lines say what went wrong.
  std::ifstream in(log);
  std::string text, line;
  for (int i = 0; i < 6 && std::getline(in, line); ++i) text += (i ? " | " : "") + line;
  return "gnuplot failed" + (text.empty() ? std::string() : ": " + text);
}

const char* KindName(GraphKind k) {
  return k == GraphKind::kXy ? "X/Y curve" : k == GraphKind::kXyz ? "3D curve" : "time graph";
}

}  // namespace

void GraphModule::WriteOutputs(const fs::path& dir) const {
  written_.clear();
  if (series_.empty()) return;
  const fs::path folder = dir / "graphs";
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw Error("cannot create '" + folder.string() + "': " + ec.message());
  // The CSV files, and the plots of the first kMaxPngs graphs that want one:
  // a gnuplot per core (at most 4), 25 plots each at least.
  const size_t processes = std::clamp<size_t>(
      std::min<size_t>(std::thread::hardware_concurrency(), (series_.size() + 24) / 25), 1, 4);
  std::vector<std::ostringstream> scripts(processes);
  for (std::ostringstream& script : scripts)
    script << "set terminal pngcairo size 900,600 noenhanced font 'sans,10'\n";
  std::vector<size_t> plotted;
  int over_cap = 0;
  std::vector<std::string> descriptions(series_.size());
  // The CSV files, robots' graphs in parallel (folders first, serially).
  for (const auto& series : series_)
    fs::create_directories((folder / series->file).parent_path(), ec);
  // Each written whole (WriteFileAtomically); "" or why not.
  std::vector<std::string> csv_failure(series_.size());
  world_->scheduler().ParallelFor(
      0, static_cast<int64_t>(series_.size()), 4, [&](int64_t begin, int64_t end) {
        for (int64_t k = begin; k < end; ++k)
          csv_failure[k] =
              TryWriteFileAtomically(folder / (series_[k]->file + ".csv"), CsvText(*series_[k]));
      });
  for (size_t k = 0; k < series_.size(); ++k) {
    const Series& s = *series_[k];
    const fs::path csv = folder / (s.file + ".csv");
    if (!csv_failure[k].empty())
      throw Error("cannot write '" + csv.string() + "': " + csv_failure[k]);
    std::string& d = descriptions[k];
    d = "graph " + s.path + ": " + KindName(s.settings.kind) + ", " +
        std::to_string(s.settings.streams.size()) + " stream" +
        (s.settings.streams.size() == 1 ? "" : "s") + ", " + std::to_string(s.count) + " sample" +
        (s.count == 1 ? "" : "s");
    if (s.dropped > 0)
      d += " (buffer full: " + std::to_string(s.dropped) +
           (s.settings.cyclic ? " earlier samples overwritten)" : " later samples not kept)");
    written_.push_back({"graph", "graphs/" + s.file + ".csv", d});
    if (!s.settings.png) continue;
    if (static_cast<int>(plotted.size()) >= kMaxPngs) {
      ++over_cap;
      continue;
    }
    const fs::path png = folder / (s.file + ".png");
    fs::remove(png, ec);  // a PNG of an earlier run in the same folder is not this one's
    PlotCommands(s, csv, png, scripts[plotted.size() % processes]);
    plotted.push_back(k);
  }
  if (over_cap > 0)
    std::cerr << "warning: graphs: PNGs drawn for the first " << kMaxPngs << " graphs only; "
              << over_cap << " more have their CSV file alone (png: false on a model's graph "
              << "avoids this note)\n";
  if (plotted.empty()) return;
  // The gnuplot processes draw them, concurrently.
  std::vector<fs::path> files;  // scripts and logs, removed afterwards
  std::vector<pid_t> pids;
  std::string failure;
  for (size_t p = 0; p < processes && p < plotted.size() && failure.empty(); ++p) {
    const fs::path gp = folder / (".plot" + std::to_string(p) + ".gp");
    const fs::path log = folder / (".plot" + std::to_string(p) + ".log");
    files.push_back(gp);
    files.push_back(log);
    std::ofstream f(gp);
    f << scripts[p].str();
    if (!f.flush()) {
      failure = "cannot write '" + gp.string() + "'";
      break;
    }
    pid_t pid = 0;
    failure = StartGnuplot(gp, log, &pid);
    if (failure.empty()) pids.push_back(pid);
  }
  for (size_t p = 0; p < pids.size(); ++p) {
    const std::string why = FinishGnuplot(pids[p], files[2 * p + 1]);
    if (failure.empty()) failure = why;
  }
  for (const fs::path& file : files) fs::remove(file, ec);
  int missing = 0;
  for (size_t k : plotted) {
    const Series& s = *series_[k];
    const fs::path png = folder / (s.file + ".png");
    if (fs::is_regular_file(png, ec) && fs::file_size(png, ec) > 0) {
      written_.push_back({"graph", "graphs/" + s.file + ".png", descriptions[k]});
    } else {
      ++missing;
      fs::remove(png, ec);
    }
  }
  if (!failure.empty() || missing > 0)
    std::cerr << "warning: graphs: " << (failure.empty() ? "gnuplot drew nothing" : failure) << "; "
              << missing << " of " << plotted.size()
              << " PNGs missing (the CSV files are written)\n";
  if (over_cap > 0)
    written_.push_back({"note", "graphs/",
                        std::to_string(over_cap) + " graphs past the first " +
                            std::to_string(kMaxPngs) + " have no PNG (CSV only)"});
}

void GraphModule::ListOutputs(std::vector<OutputFile>* out) const {
  out->insert(out->end(), written_.begin(), written_.end());
}

}  // namespace swarmsim::graphs
