// `swarmsim report DB`: per parameter point, runs, failures and the mean,
// standard deviation and 95% confidence interval of each final metric; a
// tidy CSV with one row per run; a PNG plot drawn by gnuplot.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace swarmsim {

struct ReportOptions {
  std::string db;
  std::string x;   // parameter on the x axis (default: the first that varies)
  std::string y;   // metric (default: every metric in the table, the first in the plot)
  std::string by;  // one line per value of this parameter
  std::optional<std::string> csv;
  std::optional<std::string> plot;  // .png
};

// One run as the report sees it.
struct ReportRun {
  int64_t id = 0, point = 0;
  uint64_t seed = 0;
  std::string status, error, state_hash;
  double wall_s = 0;
  int64_t steps = 0;
  std::map<std::string, std::string> params;
  std::map<std::string, double> metrics;
};

struct ReportData {
  std::string world, started_at, version;
  std::vector<std::string> param_names;           // in --param order
  std::map<std::string, std::string> param_kind;  // list | linear | log
  std::vector<std::string> metric_names;          // sorted
  std::vector<ReportRun> runs;                    // by id
  int64_t world_versions = 1;  // world files the finished runs ran (--allow-changed-world)
};

ReportData LoadReport(const std::string& db_path);

// The CSV header: run,point,seed,status,<params>,steps,wall_s,state_hash,error,<metrics>.
std::vector<std::string> CsvColumns(const ReportData& data);
void WriteCsv(const ReportData& data, std::ostream& out);

int RunReport(const ReportOptions& options, std::ostream& out, std::ostream& err);

}  // namespace swarmsim
