// Bytes that are not UTF-8 (in a world file, a script's print, error or
// metric name, a --set value) reach summary.json, metrics.csv, the sweep
// database and the console as U+FFFD; the message and the exit code stay
// the ones a user would get with clean text.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "framework/utf8.h"
#include "swarm/sweep/sqlite_db.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::FreshTempDir;
using testing::ProbeWorld;
using testing::ReadFile;
using testing::RunProgram;

constexpr const char* kReplacement = "\xEF\xBF\xBD";  // U+FFFD

// summary.json parsed; fails the test if it does not parse.
nlohmann::json Summary(const fs::path& out) {
  const std::string text = ReadFile(out / "summary.json");
  EXPECT_FALSE(text.empty()) << "summary.json is empty";
  EXPECT_TRUE(IsValidUtf8(text));
  return nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
}

TEST(InvalidUtf8Test, AWorldKeyWithABadByteIsStillABadWorld) {
  const fs::path dir = FreshTempDir("swarmsim_utf8", "key");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "arena: {size: 4, sid\xff: 1}\n";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --out " +
                            (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(std::string("sid") + kReplacement), std::string::npos) << r.output;
  EXPECT_TRUE(IsValidUtf8(r.output)) << r.output;
  const nlohmann::json summary = Summary(dir / "out");
  ASSERT_FALSE(summary.is_discarded());
  EXPECT_EQ(summary["status"], "error");
  EXPECT_NE(summary["error"].get<std::string>().find("unknown key"), std::string::npos)
      << summary["error"];
  fs::remove_all(dir);
}

TEST(InvalidUtf8Test, PrintsMetricNamesAndErrorsWithBadBytesKeepTheirOutputs) {
  const fs::path dir =
      ProbeWorld("swarmsim_utf8", "script", "",
                 "function sysCall_actuation()\n"
                 "  print('bad \\xff byte')\n"
                 "  sim.recordMetric('m\\xfe', 1)\n"
                 "  if sim.getSimulationTime() > 0.15 then error('boom \\xc3') end\n"
                 "end\n");
  const fs::path out = dir / "out";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 5 --quiet --out " +
                            out.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;  // a script error, as with clean text
  EXPECT_TRUE(IsValidUtf8(r.output)) << r.output;
  EXPECT_NE(r.output.find(std::string("[probe#0] bad ") + kReplacement + " byte"),
            std::string::npos)
      << r.output;
  const nlohmann::json summary = Summary(out);
  ASSERT_FALSE(summary.is_discarded());
  EXPECT_EQ(summary["status"], "error");
  EXPECT_NE(summary["error"].get<std::string>().find(std::string("boom ") + kReplacement),
            std::string::npos)
      << summary["error"];
  const std::string csv = ReadFile(out / "metrics.csv");
  EXPECT_TRUE(IsValidUtf8(csv));
  EXPECT_NE(csv.find(std::string("probe#0,m") + kReplacement + ",1"), std::string::npos) << csv;
  fs::remove_all(dir);
}

TEST(InvalidUtf8Test, ATextParameterWithBadBytesRunsOk) {
  const fs::path dir = FreshTempDir("swarmsim_utf8", "param");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "parameters: {label: plain}\n";
  const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                            " --steps 2 --quiet --set 'label=a\xff"
                            "b' --out " +
                            (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json summary = Summary(dir / "out");
  ASSERT_FALSE(summary.is_discarded());
  EXPECT_EQ(summary["status"], "ok");
  EXPECT_EQ(summary["parameters"]["label"], std::string("a") + kReplacement + "b");
  fs::remove_all(dir);
}

TEST(InvalidUtf8Test, TheSweepDatabaseStoresTheRealErrorAsUtf8) {
  const fs::path dir = FreshTempDir("swarmsim_utf8", "sweep");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic, time_step: 0.1}\n"
                                       "parameters: {fail: 0}\n"
                                       "models:\n  - {model: probe.yaml, position: [0, 0]}\n";
  std::ofstream(dir / "probe.yaml") << "model: probe\n"
                                       "objects: {name: body, type: dummy, script: probe.lua}\n";
  std::ofstream(dir / "probe.lua") << "function sysCall_actuation()\n"
                                      "  if sim.getParam('fail') == 1 then error('bad \\xff') end\n"
                                      "end\n";
  const fs::path db_path = dir / "sweep.db";
  const auto r = RunProgram("sweep " + (dir / "world.yaml").string() +
                            " --param fail=0,1 --steps 2 --quiet --db " + db_path.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;  // one run failed
  EXPECT_TRUE(IsValidUtf8(r.output)) << r.output;
  SqliteDb db(db_path, /*read_only=*/true);
  SqliteStatement q(&db, "SELECT status, coalesce(error, '') FROM runs ORDER BY id");
  int failed = 0, ok = 0;
  while (q.Step()) {
    const std::string error = q.Text(1);
    EXPECT_TRUE(IsValidUtf8(error)) << error;
    if (q.Text(0) == "ok") ++ok;
    if (q.Text(0) == "failed") {
      ++failed;
      EXPECT_NE(error.find(std::string("bad ") + kReplacement), std::string::npos) << error;
      EXPECT_EQ(error.find("json.exception"), std::string::npos) << error;
    }
  }
  EXPECT_EQ(ok, 1);
  EXPECT_EQ(failed, 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
