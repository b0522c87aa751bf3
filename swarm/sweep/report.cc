#include "swarm/sweep/report.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "framework/csv.h"
#include "framework/error.h"
#include "framework/output_file.h"
#include "framework/regular_file.h"
#include "framework/suggest.h"
#include "swarm/sweep/results_db.h"
#include "swarm/sweep/stats.h"

namespace swarmsim {
namespace {

// `text` right-aligned in `width` columns, counting characters, not bytes
// (setw counted 'ünï' as 5: the columns after it slipped).
std::string RightAligned(const std::string& text, size_t width) {
  size_t columns = 0;
  for (const char c : text) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return columns >= width ? text : std::string(width - columns, ' ') + text;
}

std::string Num(double v, int precision = 6) {
  if (std::isnan(v)) return "";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

bool IsNumber(const std::string& s) {
  char* end = nullptr;
  std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size();
}

// Sorts parameter values numerically when they are numbers.
bool ValueLess(const std::string& a, const std::string& b) {
  if (IsNumber(a) && IsNumber(b)) return std::stod(a) < std::stod(b);
  return a < b;
}

// For a name that is not among `valid`: " (<what>: a, b); did you mean
// 'a'?" (when one is near), or " (<none>)" when there are none.
std::string ValidNames(const std::string& name, const std::vector<std::string>& valid,
                       const std::string& what, const std::string& none) {
  if (valid.empty()) return " (" + none + ")";
  std::string list;
  for (const std::string& v : valid) list += (list.empty() ? "" : ", ") + v;
  const std::string* nearest = NearestName(name, valid);
  return " (" + what + ": " + list + ")" +
         (nearest != nullptr ? "; did you mean '" + *nearest + "'?" : std::string());
}

std::string GnuplotQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

void Plot(const ReportData& data, const ReportOptions& o, const std::string& x,
          const std::string& y, std::ostream& err) {
  // (by value, x value) -> values of y over the ok runs.
  using Key = std::pair<std::string, std::string>;
  auto less = [](const Key& a, const Key& b) {
    if (a.first != b.first) return ValueLess(a.first, b.first);
    return ValueLess(a.second, b.second);
  };
  std::map<Key, std::vector<double>, decltype(less)> groups(less);
  for (const ReportRun& r : data.runs) {
    if (r.status != "ok") continue;
    auto m = r.metrics.find(y);
    if (m == r.metrics.end() || !std::isfinite(m->second)) continue;
    groups[{o.by.empty() ? "" : r.params.at(o.by), r.params.at(x)}].push_back(m->second);
  }
  if (groups.empty()) throw Error("no finished run has metric '" + y + "' to plot");
  bool numeric_x = true;
  for (const auto& [key, v] : groups) numeric_x = numeric_x && IsNumber(key.second);

  std::ostringstream script;
  script << "set terminal pngcairo size 1000,650 enhanced font 'sans,11'\n"
         << "set output " << GnuplotQuote(*o.plot) << "\n"
         << "set title " << GnuplotQuote(y + " vs " + x + " (mean, 95% CI)") << " noenhanced\n"
         << "set xlabel " << GnuplotQuote(x) << " noenhanced\n"
         << "set ylabel " << GnuplotQuote(y) << " noenhanced\n"
         << "set grid\nset offsets 0, 0, graph 0.05, graph 0.05\n";
  if (o.by.empty())
    script << "set key off\n";
  else
    script << "set key outside right top noenhanced title " << GnuplotQuote(o.by)
           << " noenhanced\n";  // its own flag: 'a_b' is not a subscript
  const bool log_x = data.param_kind.count(x) && data.param_kind.at(x) == "log" && numeric_x;
  // Lines of different --by values are dodged sideways by 1% of the x span so
  // their error bars do not hide each other; the x range hugs the data.
  std::set<std::string> by_values;
  double x_min = INFINITY, x_max = -INFINITY;
  for (const auto& [key, v] : groups) {
    by_values.insert(key.first);
    if (numeric_x) {
      x_min = std::min(x_min, std::stod(key.second));
      x_max = std::max(x_max, std::stod(key.second));
    }
  }
  double dodge = 0;
  if (numeric_x && x_max > x_min) {
    if (log_x) {
      const double pad = std::pow(x_max / x_min, 0.06);
      script << "set logscale x\nset xrange [" << Num(x_min / pad, 10) << ":"
             << Num(x_max * pad, 10) << "]\n";
      dodge = 0.01 * std::log(x_max / x_min);
    } else {
      const double pad = 0.06 * (x_max - x_min);
      script << "set xrange [" << Num(x_min - pad, 10) << ":" << Num(x_max + pad, 10) << "]\n";
      dodge = 0.01 * (x_max - x_min);
    }
  }
  std::set<std::string, decltype(&ValueLess)> x_values(&ValueLess);
  for (const auto& [key, v] : groups) x_values.insert(key.second);
  if (numeric_x && x_values.size() <= 12) {  // a tick at each value of the sweep
    script << "set xtics (";
    for (auto it = x_values.begin(); it != x_values.end(); ++it)
      script << (it == x_values.begin() ? "" : ", ") << *it;
    script << ")\n";
  }
  auto dodged = [&](const std::string& value, int line) {
    if (!numeric_x || dodge == 0) return value;
    const double shift = (line - 0.5 * (static_cast<double>(by_values.size()) - 1)) * dodge;
    return Num(log_x ? std::stod(value) * std::exp(shift) : std::stod(value) + shift, 10);
  };
  std::vector<std::string> lines;
  int block = 0;
  std::string current;
  bool open = false;
  for (const auto& [key, values] : groups) {
    if (!open || key.first != current) {
      if (open) script << "EOD\n";
      script << "$d" << block << " << EOD\n";
      lines.push_back(
          "$d" + std::to_string(block) + " using " + (numeric_x ? "1:2:3:4" : "0:2:3:4:xtic(1)") +
          " with yerrorlines lw 2 pt 7 ps 1.2 title " + GnuplotQuote(o.by.empty() ? y : key.first));
      ++block;
      current = key.first;
      open = true;
    }
    const Summary s = Summarize(values);
    const double lo = std::isnan(s.ci_low) ? s.mean : s.ci_low;
    const double hi = std::isnan(s.ci_high) ? s.mean : s.ci_high;
    script << dodged(key.second, block - 1) << " " << Num(s.mean, 10) << " " << Num(lo, 10) << " "
           << Num(hi, 10) << "\n";
  }
  script << "EOD\nplot ";
  for (size_t i = 0; i < lines.size(); ++i) script << (i ? ", \\\n     " : "") << lines[i];
  script << "\n";

  // gnuplot draws on its stdout when it cannot open the file: a folder
  // that is not there is refused first, and its stdout goes nowhere (its
  // messages, on stderr, to ours).
  const std::filesystem::path folder = std::filesystem::path(*o.plot).parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder))
    throw Error("cannot write the plot '" + *o.plot + "': no folder '" + folder.string() + "'");
  FILE* gp = popen("gnuplot >/dev/null", "w");
  if (!gp) throw Error("cannot run gnuplot; install gnuplot-nox (tools/setup.sh)");
  const std::string text = script.str();
  fwrite(text.data(), 1, text.size(), gp);
  const int status = pclose(gp);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error(WIFEXITED(status) && WEXITSTATUS(status) == 127
                    ? "gnuplot not found; install gnuplot-nox (tools/setup.sh)"
                    : "gnuplot failed to draw '" + *o.plot + "'");
  err << "plot: " << *o.plot << "\n";
}

}  // namespace

ReportData LoadReport(const std::string& db_path) {
  if (!std::ifstream(db_path)) throw Error("no database '" + db_path + "'");
  ResultsDb results(db_path, /*read_only=*/true);
  const std::optional<SweepRecord> sweep = results.ReadSweep();
  if (!sweep) throw Error("'" + db_path + "' holds no sweep");
  ReportData d;
  d.world = sweep->world_path;
  d.started_at = sweep->started_at;
  d.version = sweep->version;
  const nlohmann::json space = nlohmann::json::parse(sweep->space_json);
  for (const auto& p : space.at("params")) {
    d.param_names.push_back(p.at("name"));
    d.param_kind[p.at("name")] = p.at("kind");
  }
  SqliteDb& db = results.db();
  SqliteStatement q(&db,
                    "SELECT id, point, seed, status, coalesce(error, ''), coalesce(wall_s, 0), "
                    "coalesce(steps, 0), coalesce(state_hash, '') FROM runs ORDER BY id");
  std::map<int64_t, size_t> index;
  while (q.Step()) {
    ReportRun r;
    r.id = q.Int(0);
    r.point = q.Int(1);
    r.seed = static_cast<uint64_t>(q.Int(2));
    r.status = q.Text(3);
    r.error = q.Text(4);
    r.wall_s = q.Double(5);
    r.steps = q.Int(6);
    r.state_hash = q.Text(7);
    index[r.id] = d.runs.size();
    d.runs.push_back(std::move(r));
  }
  SqliteStatement p(&db, "SELECT run, name, value FROM run_params");
  while (p.Step()) d.runs[index.at(p.Int(0))].params[p.Text(1)] = p.Text(2);
  std::set<std::string> metrics;
  SqliteStatement m(&db, "SELECT run, metric, value FROM final_metrics");
  while (m.Step()) {
    d.runs[index.at(m.Int(0))].metrics[m.Text(1)] = m.IsNull(2) ? std::nan("") : m.Double(2);
    metrics.insert(m.Text(1));
  }
  d.metric_names.assign(metrics.begin(), metrics.end());
  d.world_versions = results.WorldVersions();
  return d;
}

std::vector<std::string> CsvColumns(const ReportData& d) {
  std::vector<std::string> c{"run", "point", "seed", "status"};
  c.insert(c.end(), d.param_names.begin(), d.param_names.end());
  for (const char* s : {"steps", "wall_s", "state_hash", "error"}) c.push_back(s);
  c.insert(c.end(), d.metric_names.begin(), d.metric_names.end());
  return c;
}

void WriteCsv(const ReportData& d, std::ostream& out) {
  const std::vector<std::string> columns = CsvColumns(d);
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << CsvField(columns[i]);
  out << "\n";
  for (const ReportRun& r : d.runs) {
    if (r.status != "ok" && r.status != "failed") continue;  // not run yet
    out << r.id << ',' << r.point << ',' << r.seed << ',' << r.status;
    for (const std::string& name : d.param_names) out << ',' << CsvField(r.params.at(name));
    out << ',' << r.steps << ',' << Num(r.wall_s, 6) << ',' << r.state_hash << ','
        << CsvField(r.error);
    for (const std::string& name : d.metric_names) {
      auto it = r.metrics.find(name);
      out << ',' << (it == r.metrics.end() ? "" : Num(it->second, 12));
    }
    out << "\n";
  }
}

namespace {

// --csv and --plot write files: never over the database (or the log files
// SQLite keeps beside it), nor both into one file.
void CheckReportOutputs(const ReportOptions& o) {
  for (const auto& [flag, file] : {std::pair{"--csv", &o.csv}, std::pair{"--plot", &o.plot}}) {
    if (!*file) continue;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"})
      if (SameFile(**file, o.db + suffix))
        throw Error(std::string(flag) + ": '" + **file + "' is the sweep's database" +
                    (*suffix != 0 ? std::string("'s log file (") + suffix + ")" : "") +
                    ", which it would overwrite: name another file");
  }
  if (o.csv && o.plot && SameFile(*o.csv, *o.plot))
    throw Error("--csv and --plot name one file ('" + *o.csv + "'): name two");
}

}  // namespace

int RunReport(const ReportOptions& o, std::ostream& out, std::ostream& err) {
  CheckReportOutputs(o);
  const ReportData d = LoadReport(o.db);
  for (const std::string* name : {&o.x, &o.by})
    if (!name->empty() &&
        std::find(d.param_names.begin(), d.param_names.end(), *name) == d.param_names.end())
      throw Error("'" + *name + "' is not a parameter of this sweep" +
                  ValidNames(*name, d.param_names, "its parameters",
                             "it has none: it was run without --param"));
  if (!o.y.empty() &&
      std::find(d.metric_names.begin(), d.metric_names.end(), o.y) == d.metric_names.end())
    throw Error("no run recorded metric '" + o.y + "'" +
                ValidNames(o.y, d.metric_names, "the metrics recorded", "no run recorded any"));
  std::vector<std::string> metrics = o.y.empty() ? d.metric_names : std::vector{o.y};

  int64_t finished = 0, failed = 0;
  for (const ReportRun& r : d.runs) {
    finished += r.status == "ok" || r.status == "failed";
    failed += r.status == "failed";
  }
  out << "sweep of " << d.world << " (started " << d.started_at << ", swarmsim " << d.version
      << "): " << finished << " of " << d.runs.size() << " runs finished, " << failed
      << " failed\n";
  if (d.world_versions > 1)
    out << "note: these runs ran " << d.world_versions << " versions of the world file (the "
        << "sweep was resumed with --allow-changed-world; runs.world_hash tells which)\n";

  // Per point: the runs of each parameter combination.
  std::map<int64_t, std::vector<const ReportRun*>> points;
  for (const ReportRun& r : d.runs)
    if (r.status == "ok" || r.status == "failed") points[r.point].push_back(&r);
  for (const std::string& metric : metrics) {
    out << "\n" << metric << " (final value; mean, sd and 95% CI over ok runs)\n";
    for (const std::string& name : d.param_names) out << RightAligned(name, 12) << " ";
    out << std::setw(5) << "runs" << std::setw(7) << "failed" << std::setw(13) << "mean"
        << std::setw(12) << "sd" << std::setw(13) << "ci95_low" << std::setw(13) << "ci95_high"
        << "\n";
    for (const auto& [point, runs] : points) {
      std::vector<double> values;
      int64_t bad = 0;
      for (const ReportRun* r : runs) {
        if (r->status != "ok") {
          ++bad;
          continue;
        }
        auto it = r->metrics.find(metric);
        if (it != r->metrics.end() && std::isfinite(it->second)) values.push_back(it->second);
      }
      const Summary s = Summarize(values);
      for (const std::string& name : d.param_names)
        out << RightAligned(runs.front()->params.at(name), 12) << " ";
      auto cell = [](double v, int w) {
        std::ostringstream c;
        c << std::setw(w) << (std::isnan(v) ? std::string("-") : Num(v, 6));
        return c.str();
      };
      out << std::setw(5) << runs.size() << std::setw(7) << bad << cell(s.mean, 13)
          << cell(s.sd, 12) << cell(s.ci_low, 13) << cell(s.ci_high, 13) << "\n";
    }
  }
  // Failures, briefly.
  int shown = 0;
  for (const ReportRun& r : d.runs) {
    if (r.status != "failed") continue;
    if (shown++ == 0) out << "\nfailed runs\n";
    if (shown > 10) {
      out << "  ... " << failed - 10 << " more (see the CSV)\n";
      break;
    }
    out << "  run " << r.id << " seed " << r.seed << ": " << r.error << "\n";
  }
  out << std::flush;

  if (o.csv) {
    std::ofstream f(*o.csv);
    if (!f) throw Error(CannotWrite(*o.csv));
    WriteCsv(d, f);
    err << "csv: " << *o.csv << " (one row per run)\n";
  }
  if (o.plot) {
    std::string x = o.x;
    if (x.empty()) {
      std::map<std::string, std::set<std::string>> distinct;
      for (const ReportRun& r : d.runs)
        for (const auto& [name, value] : r.params) distinct[name].insert(value);
      for (const std::string& name : d.param_names)
        if (name != o.by && distinct[name].size() > 1) {
          x = name;
          break;
        }
      if (x.empty() && !d.param_names.empty()) x = d.param_names.front();
    }
    if (x.empty()) throw Error("the sweep has no parameters to plot against; pass --param");
    if (metrics.empty()) throw Error("no metrics recorded; nothing to plot");
    std::vector<std::string> pooled;
    for (const std::string& name : d.param_names)
      if (name != x && name != o.by) pooled.push_back(name);
    if (!pooled.empty()) {
      err << "plot: pooling runs over";
      for (const std::string& name : pooled) err << " " << name;
      err << " (use --by to separate one)\n";
    }
    Plot(d, o, x, metrics.front(), err);
  }
  return 0;
}

}  // namespace swarmsim
