// A run's graph files (modules/graphs/outputs.cc): graphs/<path>.csv with a
// header and one row per sample (numbers that read back exactly, nan for
// no reading, names quoted as CSV needs), the outputs listed with what
// they hold, and a robot's graph in its robot's folder.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "modules/force_sensor/force_sensor.h"
#include "modules/graphs/module.h"
#include "modules/graphs/rows.h"
#include "tests/modules/module_world.h"

namespace swarmsim::graphs {
namespace {

using testing::ModuleWorld;
using testing::ReadFile;
using testing::TempDir;

constexpr double kStep = 0.125;

GraphRow Graph(const std::vector<std::string>& streams) {
  GraphRow row;
  for (const std::string& s : streams) ParseStream(s, &row.streams);
  row.png = false;  // CSV only: the PNGs are gnuplot's
  return row;
}

// Two steps of a box moved to x = 0.1 and then 1e-7; a graph of its x, a
// stream named with a comma and quote, and a script stream nobody sets.
TEST(GraphOutputsTest, TheCsvHoldsEverySampleExactly) {
  ModuleWorld w("kinematic", 1, kStep);
  const ObjectId box = w.Box("box", {}, {}, {0.1, 0.1, 0.1});
  GraphRow row = Graph({"position /box x", "script quiet"});
  row.streams[0].name = "x, \"box\"";
  w.Add("graph", "trace", {}, {}, &row);
  ASSERT_EQ(w.Run(0), "");
  w.scene().SetLocalPose(box, {{0.1, 0, 0}, {}});
  ASSERT_EQ(w.Run(1), "");
  w.scene().SetLocalPose(box, {{1e-7, 0, 0}, {}});
  ASSERT_EQ(w.Run(1), "");
  TempDir dir;
  w.world().WriteOutputs(dir.path());
  EXPECT_EQ(ReadFile(dir.path() / "graphs" / "trace.csv"),
            "time,\"x, \"\"box\"\"\",quiet\n"
            "0,0,nan\n"
            "0.125,0.1,nan\n"
            "0.25,1e-07,nan\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "graphs" / "trace.png"));
  const std::vector<OutputFile> outputs = w.world().ListOutputs();
  ASSERT_EQ(outputs.size(), 1u);
  EXPECT_EQ(outputs[0].kind, "graph");
  EXPECT_EQ(outputs[0].path, "graphs/trace.csv");
  EXPECT_EQ(outputs[0].description, "graph /trace: time graph, 2 streams, 3 samples");
}

// A force stream reads what sim.readForceSensor reads: nan without a
// reading, the force while the link holds, 0 once it broke (it had gone on
// with the last force before the break).
TEST(GraphOutputsTest, AForceStreamReadsZeroOnceTheLinkBroke) {
  ModuleWorld w("kinematic", 1, kStep);
  const ObjectId beam = w.Box("beam", {}, {}, {0.1, 0.1, 0.1});
  const ForceSensorData settings;
  const ObjectId hook = w.Add("force_sensor", "hook", beam, {}, &settings);
  GraphRow row = Graph({"force /beam/hook z"});
  w.Add("graph", "load", {}, {}, &row);
  ForceSensorData& sensor = w.RowOf<ForceSensorData>("force_sensor", hook);
  ASSERT_EQ(w.Run(0), "");  // no reading: nothing simulates the link
  sensor.has_reading = true;
  sensor.force = {0, 0, 19.62};
  ASSERT_EQ(w.Run(1), "");
  sensor.broken = true;
  ASSERT_EQ(w.Run(1), "");
  TempDir dir;
  w.world().WriteOutputs(dir.path());
  EXPECT_EQ(ReadFile(dir.path() / "graphs" / "load.csv"),
            "time,force /beam/hook z\n"
            "0,nan\n"
            "0.125,19.62\n"
            "0.25,0\n");
}

TEST(GraphOutputsTest, ARobotsGraphIsInItsRobotsFolderAndAFullBufferIsSaid) {
  ModuleWorld w("kinematic", 1, kStep);
  const ObjectId bot = w.Robot("bot", {});
  GraphRow row = Graph({"script speed"});
  row.kind = GraphKind::kTime;
  row.buffer = 2;
  w.Add("graph", "trace", bot, {}, &row);
  GraphRow cyclic = Graph({"position : x", "position : y"});
  cyclic.kind = GraphKind::kXy;
  cyclic.buffer = 1;
  cyclic.cyclic = true;
  w.Add("graph", "path", bot, {}, &cyclic);
  ASSERT_EQ(w.Run(3), "");
  TempDir dir;
  w.world().WriteOutputs(dir.path());
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "graphs" / "bot" / "trace.csv"));
  EXPECT_EQ(ReadFile(dir.path() / "graphs" / "bot" / "path.csv"),
            "time,position : x,position : y\n0.375,0,0\n");
  const std::vector<OutputFile> outputs = w.world().ListOutputs();
  ASSERT_EQ(outputs.size(), 2u);
  EXPECT_EQ(outputs[0].path, "graphs/bot/trace.csv");
  EXPECT_EQ(outputs[0].description,
            "graph /bot/trace: time graph, 1 stream, 2 samples (buffer full: 2 later samples not "
            "kept)");
  EXPECT_EQ(outputs[1].description,
            "graph /bot/path: X/Y curve, 2 streams, 1 sample (buffer full: 3 earlier samples "
            "overwritten)");
}

TEST(GraphOutputsTest, AWorldWithoutGraphsWritesNoGraphsFolder) {
  ModuleWorld w;
  ASSERT_EQ(w.Run(1), "");
  TempDir dir;
  w.world().WriteOutputs(dir.path());
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "graphs"));
  EXPECT_TRUE(w.world().ListOutputs().empty());
}

}  // namespace
}  // namespace swarmsim::graphs
