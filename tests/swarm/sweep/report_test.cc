// `swarmsim report DB` (swarm/sweep/report.cc): the table, the tidy CSV and the
// plot, and the valid names listed with the nearest for a typo.
#include "swarm/sweep/report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "swarm/sweep/coordinator.h"
#include "swarm/sweep/grid.h"
#include "swarm/sweep/results_db.h"
#include "swarm/sweep/stats.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/run_program.h"
#include "tests/swarm/sweep/sweep_db.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

using Result = swarmsim::testing::CommandResult;
using swarmsim::testing::RunCommand;
using swarmsim::testing::RunProgram;
using sweep_testing::Count;
using sweep_testing::kWorld;
using sweep_testing::ReadRuns;
using sweep_testing::RunRow;
using sweep_testing::TempDir;

TEST(SweepTest, ReportTableCsvColumnsAndPlot) {
  const fs::path dir = TempDir("report");
  const fs::path db = dir / "r.db";
  Result r = RunProgram("sweep " + kWorld + " --param robots=2,4 --param fail_at=-1,0.3 " +
                        "--seeds 3 --steps 8 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 1) << r.output;  // the fail_at=0.3 runs fail, as planned
  const fs::path csv = dir / "runs.csv", png = dir / "plot.png";
  r = RunProgram("report " + db.string() + " --x robots --by fail_at --y x --csv " + csv.string() +
                 (RunCommand("command -v gnuplot").exit_code == 0 ? " --plot " + png.string()
                                                                  : std::string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // Reading leaves nothing beside the database (no empty -wal/-shm files).
  EXPECT_FALSE(fs::exists(db.string() + "-wal"));
  EXPECT_FALSE(fs::exists(db.string() + "-shm"));
  EXPECT_NE(r.output.find("12 of 12 runs finished, 6 failed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ci95_low"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("planned failure"), std::string::npos) << r.output;
  std::ifstream f(csv);
  std::string header, line;
  std::getline(f, header);
  EXPECT_EQ(header,
            "run,point,seed,status,robots,fail_at,steps,wall_s,state_hash,error,"
            "mean_nearest_neighbor_distance,x");
  int rows = 0, failed = 0;
  while (std::getline(f, line)) {
    ++rows;
    // Runs are numbered from 1, in the CSV as in the database.
    EXPECT_EQ(line.substr(0, line.find(',')), std::to_string(rows)) << line;
    failed += line.find(",failed,") != std::string::npos;
  }
  EXPECT_EQ(rows, 12);
  EXPECT_EQ(failed, 6);
  if (fs::exists(png)) {
    std::ifstream p(png, std::ios::binary);
    char magic[8] = {};
    p.read(magic, 8);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  } else {
    std::cout << "gnuplot not installed: plot not checked\n";
  }
  // A plot into a folder that is not there: refused, and no PNG on stdout
  // (gnuplot draws there when it cannot open the file).
  r = RunProgram("report " + db.string() + " --x robots --y x --plot " +
                 (dir / "no/p.png").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("cannot write the plot '" + (dir / "no/p.png").string() +
                          "': no folder '" + (dir / "no").string() + "'"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("PNG"), std::string::npos) << r.output;
  r = RunProgram("report " + db.string() + " --by nosuch");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  fs::remove_all(dir);
}

TEST(SweepTest, ReportListsTheValidNamesAndSuggestsTheNearest) {
  const fs::path dir = TempDir("report_names");
  const fs::path db = dir / "r.db";
  Result r = RunProgram("sweep " + kWorld + " --param robots=2,3 --param fail_at=-1 " +
                        "--steps 4 --quiet --db " + db.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunProgram("report " + db.string() + " --y mnnd");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("no run recorded metric 'mnnd' (the metrics recorded: "
                          "mean_nearest_neighbor_distance, x)"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --y mean_nearest_neighbour_distance");
  EXPECT_NE(r.output.find("no run recorded metric 'mean_nearest_neighbour_distance' (the metrics "
                          "recorded: mean_nearest_neighbor_distance, x); did you mean "
                          "'mean_nearest_neighbor_distance'?"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --x robts");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("'robts' is not a parameter of this sweep (its parameters: robots, "
                          "fail_at); did you mean 'robots'?"),
            std::string::npos)
      << r.output;
  r = RunProgram("report " + db.string() + " --by seed");
  EXPECT_NE(r.output.find("'seed' is not a parameter of this sweep (its parameters: robots, "
                          "fail_at)"),
            std::string::npos)
      << r.output;
  fs::remove_all(dir);
}

// A sweep of robots=2,4 x seeds 1..3 (runs 1-6): runs 1-3 ok with x = 1, 2
// and 3; run 4 ok with x = 10; run 5 failed; run 6 not run yet.
// A sweep database of `spec` x `seeds` whose runs 1..`finished` are complete,
// each as `outcome` makes it (its id set).
fs::path SweepDb(const std::string& name, const std::string& spec,
                 const std::vector<uint64_t>& seeds, int64_t finished,
                 const std::function<void(RunOutcome*)>& outcome) {
  const fs::path file = TempDir(name) / "r.db";
  const std::vector<ParamSpec> params = {ParseParamSpec(spec)};
  ResultsDb db(file);
  db.CreateSweep({"w.yaml", "0", SweepSpace(params, seeds, 10, std::nullopt),
                  "2026-01-02T03:04:05Z", "9.9.9", "swarmsim sweep w.yaml"},
                 ExpandGrid(params, seeds));
  for (int64_t id = 1; id <= finished; ++id) {
    RunOutcome o;
    o.id = id;
    o.ok = true;
    o.steps = 10;
    o.state_hash = "00000000000000a" + std::to_string(id);
    outcome(&o);
    db.Complete(o);
  }
  return file;
}

fs::path SmallSweep(const std::string& name) {
  return SweepDb(name, "robots=2,4", {1, 2, 3}, 5, [](RunOutcome* o) {
    o->ok = o->id != 5;
    if (o->ok) o->final_metrics["x"] = o->id == 4 ? 10 : static_cast<double>(o->id);
    if (!o->ok) {
      o->state_hash.clear();
      o->error = "said \"no\", then stopped";
    }
  });
}

// What Num() prints for a statistic (6 significant digits).
std::string Shown(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

std::vector<std::string> Words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

TEST(ReportTest, TheDatabaseReadsBackAsTheSweepRanIt) {
  const fs::path file = SmallSweep("report_load");
  const ReportData d = LoadReport(file.string());
  EXPECT_EQ(d.world, "w.yaml");
  EXPECT_EQ(d.version, "9.9.9");
  EXPECT_EQ(d.param_names, std::vector<std::string>{"robots"});
  EXPECT_EQ(d.param_kind.at("robots"), "list");
  EXPECT_EQ(d.metric_names, std::vector<std::string>{"x"});
  ASSERT_EQ(d.runs.size(), 6u);
  EXPECT_EQ(d.runs[4].status, "failed");
  EXPECT_EQ(d.runs[4].seed, 2u);
  EXPECT_EQ(d.runs[4].params.at("robots"), "4");
  EXPECT_EQ(d.runs[5].status, "pending");
  EXPECT_EQ(d.runs[3].metrics.at("x"), 10);
  // The CSV: finished runs only, fields with commas or quotes quoted.
  std::ostringstream csv;
  WriteCsv(d, csv);
  std::istringstream lines(csv.str());
  std::vector<std::string> rows;
  for (std::string line; std::getline(lines, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 6u) << csv.str();
  EXPECT_EQ(rows[0], "run,point,seed,status,robots,steps,wall_s,state_hash,error,x");
  EXPECT_EQ(rows[1], "1,0,1,ok,2,10,0,00000000000000a1,,1");
  EXPECT_EQ(rows[5], "5,1,2,failed,4,10,0,,\"said \"\"no\"\", then stopped\",");
  fs::remove_all(file.parent_path());
}

TEST(ReportTest, TheTableSummarisesEachPointOverItsOkRuns) {
  const fs::path file = SmallSweep("report_table");
  std::ostringstream out, err;
  ReportOptions options;
  options.db = file.string();
  ASSERT_EQ(RunReport(options, out, err), 0) << err.str();
  const std::string text = out.str();
  EXPECT_EQ(text.rfind("sweep of w.yaml (started 2026-01-02T03:04:05Z, swarmsim 9.9.9): 5 of 6 "
                       "runs finished, 1 failed\n",
                       0),
            0u)
      << text;
  std::istringstream in(text);
  std::vector<std::vector<std::string>> table;
  for (std::string line; std::getline(in, line);)
    if (Words(line).size() == 7) table.push_back(Words(line));
  ASSERT_EQ(table.size(), 3u) << text;  // the header and two points
  EXPECT_EQ(table[0], (std::vector<std::string>{"robots", "runs", "failed", "mean", "sd",
                                                "ci95_low", "ci95_high"}));
  const Summary two = Summarize({1, 2, 3});
  EXPECT_EQ(table[1], (std::vector<std::string>{"2", "3", "0", Shown(two.mean), Shown(two.sd),
                                                Shown(two.ci_low), Shown(two.ci_high)}));
  // One ok run: a mean, and no spread to show.
  EXPECT_EQ(table[2], (std::vector<std::string>{"4", "2", "1", "10", "-", "-", "-"}));
  EXPECT_NE(text.find("\nfailed runs\n  run 5 seed 2: said \"no\", then stopped\n"),
            std::string::npos)
      << text;
  fs::remove_all(file.parent_path());
}

// --csv or --plot naming the database would overwrite every result in it
// (exit 0, "csv: sw.db"): refused before anything is written, as the
// database's log files and one file named by both.
TEST(ReportTest, TheCsvAndThePlotNeverOverwriteTheDatabase) {
  const fs::path file = SmallSweep("report_own_db");
  const auto size = fs::file_size(file);
  const auto refused = [&](std::optional<std::string> csv, std::optional<std::string> plot) {
    std::ostringstream out, err;
    ReportOptions options;
    options.db = file.string();
    options.csv = std::move(csv);
    options.plot = std::move(plot);
    return testing::ErrorOf([&] { RunReport(options, out, err); });
  };
  EXPECT_CONTAINS(refused(file.string(), std::nullopt),
                  "--csv: '" + file.string() +
                      "' is the sweep's database, which it would "
                      "overwrite: name another file");
  // Another name of it.
  const std::string dotted = (file.parent_path() / "." / file.filename()).string();
  EXPECT_CONTAINS(refused(std::nullopt, dotted),
                  "--plot: '" + dotted + "' is the sweep's database");
  EXPECT_CONTAINS(refused(file.string() + "-wal", std::nullopt),
                  "is the sweep's database's log file (-wal)");
  const std::string csv = (file.parent_path() / "r.csv").string();
  EXPECT_CONTAINS(refused(csv, csv), "--csv and --plot name one file");
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_EQ(fs::file_size(file), size);
  // Still a database.
  std::ostringstream out, err;
  ReportOptions options;
  options.db = file.string();
  EXPECT_EQ(RunReport(options, out, err), 0) << err.str();
  fs::remove_all(file.parent_path());
}

// Columns line up with values of characters past ASCII ('ünï' took 5 of
// the 12 columns, by its bytes, and the columns after it slipped).
TEST(ReportTest, ColumnsLineUpWithCharactersPastAscii) {
  const fs::path file = SweepDb("report_unicode", "label=abc,ünï,日本", {1}, 3,
                                [](RunOutcome* o) { o->final_metrics["x"] = 1; });
  std::ostringstream out, err;
  ReportOptions options;
  options.db = file.string();
  ASSERT_EQ(RunReport(options, out, err), 0) << err.str();
  std::istringstream in(out.str());
  std::vector<size_t> columns;  // where "runs" or a row's run count ends, in characters
  for (std::string line; std::getline(in, line);) {
    if (line.find("label") == std::string::npos && line.find("abc") == std::string::npos &&
        line.find("\xc3\xbc") == std::string::npos &&
        line.find("\xe6\x97\xa5") == std::string::npos)
      continue;
    // The end of the second word (the runs column), in characters.
    size_t at = line.find_first_not_of(' ');
    at = line.find_first_not_of(' ', line.find(' ', at));
    at = std::min(line.find(' ', at), line.size());
    size_t characters = 0;
    for (const char c : line.substr(0, at))
      characters += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    columns.push_back(characters);
  }
  ASSERT_EQ(columns.size(), 4u) << out.str();  // the header and three points
  for (size_t c : columns) EXPECT_EQ(c, columns[0]) << out.str();
  fs::remove_all(file.parent_path());
}

TEST(ReportTest, WhatIsNoSweepDatabaseIsSaid) {
  const fs::path dir = TempDir("report_none");
  const auto error = [](const fs::path& file) {
    try {
      LoadReport(file.string());
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error(dir / "none.db"), "no database '" + (dir / "none.db").string() + "'");
  { SqliteDb other(dir / "other.db"); }
  EXPECT_EQ(error(dir / "other.db"), "'" + (dir / "other.db").string() + "' holds no sweep");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
