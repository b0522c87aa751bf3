// Graph objects as a user meets them (modules/graphs): a world whose robots
// carry graphs is run with --out, and the CSV files, PNGs and summary.json
// are read back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/swarm/run_program.h"

namespace {

namespace fs = std::filesystem;
using swarmsim::testing::FreshTempDir;
using swarmsim::testing::ReadFile;
using swarmsim::testing::RunProgram;

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) cells.push_back(cell);
  return cells;
}

Csv ReadCsv(const fs::path& file) {
  Csv csv;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return csv;
  csv.header = Split(line);
  while (std::getline(in, line)) {
    std::vector<double> row;
    for (const std::string& cell : Split(line)) row.push_back(std::stod(cell));
    csv.rows.push_back(row);
  }
  return csv;
}

std::string HashOf(const std::string& output) {
  const size_t at = output.find("state-hash: ");
  return at == std::string::npos ? "" : output.substr(at + 12, 16);
}

// `swarmsim run DIR/world.yaml --steps STEPS --quiet --out DIR/out`.
swarmsim::testing::CommandResult RunWorld(const fs::path& dir, int steps) {
  return RunProgram("run " + (dir / "world.yaml").string() + " --steps " + std::to_string(steps) +
                    " --quiet --out " + (dir / "out").string());
}

// A PNG file: its signature and a nonzero size.
bool IsPng(const fs::path& file) {
  const std::string bytes = ReadFile(file);
  return bytes.size() > 100 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
}

// A world folder: world.yaml and the model bot.yaml (a dummy moved +x by
// `speed` m/s by bot.lua, with a velocity joint `wheel` at 0.5 rad/s and
// the graphs `graphs`, a YAML list of object entries), 3 copies.
fs::path BotWorld(const std::string& name, const std::string& graphs,
                  const std::string& world_extra = "", const std::string& lua_extra = "") {
  const fs::path dir = FreshTempDir("swarmsim_graphs", name);
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: 0.1, seed: 3}\n"
         "models:\n"
         "  - {model: bot.yaml, count: 3, distribute: {region: {min: [-3, -3], max: [3, 3]}}}\n"
      << world_extra;
  std::ofstream(dir / "bot.yaml")
      << "model: bot\n"
         "parameters: {speed: 0.2}\n"
         "objects:\n"
         "  name: body\n"
         "  type: shape\n"
         "  shape: box\n"
         "  size: [0.1, 0.1, 0.1]\n"
         "  script: bot.lua\n"
         "  children:\n"
         "    - {name: wheel, type: joint, joint: revolute, mode: velocity, target_velocity: 0.5}\n"
      << graphs;
  std::ofstream(dir / "bot.lua") << "function sysCall_init()\n"
                                    "  self = sim.getObject('.')\n"
                                    "end\n"
                                    "function sysCall_actuation()\n"
                                    "  local p = sim.getObjectPosition(self, -1)\n"
                                    "  p[1] = p[1] + sim.getParam('speed') * 0.1\n"
                                    "  sim.setObjectPosition(self, -1, p)\n"
                                    "  sim.recordMetric('x', p[1])\n"
                                    "end\n"
                                 << lua_extra;
  return dir;
}

TEST(GraphsRunTest, TimeGraphHoldsTheValuesTheObjectsHad) {
  const fs::path dir = BotWorld(
      "time", "    - {name: trace, type: graph, streams: [\"position : x\", \"joint :/wheel\"]}\n");
  const auto r = RunWorld(dir, 20);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // One file per copy, named after the graph's path.
  for (int k = 0; k < 3; ++k) {
    const fs::path csv = dir / "out/graphs" / ("bot#" + std::to_string(k)) / "trace.csv";
    ASSERT_TRUE(fs::exists(csv)) << csv;
  }
  const Csv csv = ReadCsv(dir / "out/graphs/bot#1/trace.csv");
  ASSERT_EQ(csv.header, (std::vector<std::string>{"time", "position : x", "joint :/wheel"}));
  ASSERT_EQ(csv.rows.size(), 21u);  // the start, then every step
  // x grows by speed * dt each step; the joint turns at 0.5 rad/s.
  for (size_t i = 0; i < csv.rows.size(); ++i) {
    EXPECT_NEAR(csv.rows[i][0], 0.1 * static_cast<double>(i), 1e-9);
    EXPECT_NEAR(csv.rows[i][1] - csv.rows[0][1], 0.02 * static_cast<double>(i), 1e-9);
    EXPECT_NEAR(csv.rows[i][2], 0.05 * static_cast<double>(i), 1e-9);
  }
  // The position is the one the script set (metrics.csv's x, 10 digits, of
  // step s, the step that ends at sample s + 1).
  int compared = 0;
  for (const auto& m : swarmsim::testing::ReadMetricsCsv(dir / "out/metrics.csv")) {
    if (m.robot != "bot#1" || m.metric != "x") continue;
    EXPECT_NEAR(m.value, csv.rows.at(m.step + 1)[1], 1e-9) << "step " << m.step;
    ++compared;
  }
  EXPECT_EQ(compared, 20);
}

TEST(GraphsRunTest, CurvesHaveTheirColumnsAndPngsAndSummaryListsThem) {
  const fs::path dir =
      BotWorld("curves",
               "    - {name: xy, type: graph, kind: xy, streams: [\"position : x\", \"position : "
               "y\"]}\n"
               "    - {name: tip, type: graph, kind: xyz, streams: [\"p = position :\"]}\n"
               "    - {name: flat, type: graph, streams: [\"position : z\"], png: false}\n");
  const auto r = RunWorld(dir, 10);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path g = dir / "out/graphs/bot#2";
  EXPECT_EQ(ReadCsv(g / "xy.csv").header,
            (std::vector<std::string>{"time", "position : x", "position : y"}));
  EXPECT_EQ(ReadCsv(g / "tip.csv").header, (std::vector<std::string>{"time", "p.x", "p.y", "p.z"}));
  EXPECT_EQ(ReadCsv(g / "tip.csv").rows.size(), 11u);
  EXPECT_TRUE(IsPng(g / "xy.png"));
  EXPECT_TRUE(IsPng(g / "tip.png"));
  EXPECT_FALSE(fs::exists(g / "flat.png"));  // png: false
  EXPECT_TRUE(fs::exists(g / "flat.csv"));
  // summary.json lists every file written, nothing else.
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(dir / "out/summary.json"));
  std::set<std::string> listed;
  for (const auto& o : summary.at("outputs"))
    if (o.at("kind") == "graph") listed.insert(o.at("path").get<std::string>());
  std::set<std::string> on_disk;
  for (const auto& e : fs::recursive_directory_iterator(dir / "out/graphs"))
    if (e.is_regular_file()) on_disk.insert(fs::relative(e.path(), dir / "out").string());
  EXPECT_EQ(listed, on_disk);
  EXPECT_EQ(listed.size(), 3u * 5u);  // 3 CSV + 2 PNG per copy
}

TEST(GraphsRunTest, ScriptStreamsDistancesAndCopiesAtRunTime) {
  // bot#0 copies itself at step 5 and removes bot#2 at step 10; a scene
  // graph follows the distance between bot#0's body and a wall.
  const fs::path dir = BotWorld(
      "script", "    - {name: g, type: graph, streams: [\"script speed\", \"twice = script\"]}\n",
      "obstacles:\n"
      "  - {name: wall, shape: box, size: [0.1, 20, 1], position: [10, 0, 0.5]}\n"
      "objects:\n"
      "  - {name: gap, type: distance, between: [/bot#0, /wall]}\n"
      "  - {name: clearance, type: graph, streams: [\"distance /gap\"]}\n",
      "function sysCall_sensing()\n"
      "  local g = sim.getObject('./g')\n"
      "  local t = sim.getSimulationTime()\n"
      "  if math.floor(t * 10 + 0.5) % 2 == 0 then sim.setGraphStreamValue(g, 'speed', t) end\n"
      "  sim.setGraphStreamValue(g, sim.addGraphStream(g, 'twice'), 2 * t)\n"
      "  if sim.getObjectName(self) == 'bot#0' then\n"
      "    local step = math.floor(t * 10 + 0.5)\n"
      "    if step == 5 then sim.copyModel(self) end\n"
      "    if step == 10 then sim.removeModel(sim.getObject('/bot#2')) end\n"
      "    if step == 10 then\n"
      "      local t, v = sim.getGraphStreamValues(g, 'twice', 3)\n"
      "      print(string.format('read %d %.1f %.1f', #t, t[1], v[3]))\n"
      "    end\n"
      "  end\n"
      "end\n");
  const auto r = RunWorld(dir, 20);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // sim.getGraphStreamValues at step 10 read the last 3 samples (the
  // steps ending at 0.8, 0.9 and 1.0 s; 'twice' was 2 t at their sensing).
  EXPECT_NE(r.output.find("[bot#0] read 3 0.8 1.8"), std::string::npos) << r.output;
  // A value set in a step is the sample of that step; unset: nan.
  const Csv g0 = ReadCsv(dir / "out/graphs/bot#0/g.csv");
  ASSERT_EQ(g0.rows.size(), 21u);
  EXPECT_TRUE(std::isnan(g0.rows[0][1]));  // the start: no script ran yet
  for (size_t i = 1; i < g0.rows.size(); ++i) {
    const double t_sensed = 0.1 * static_cast<double>(i - 1);  // sensing sees the step's start
    if ((i - 1) % 2 == 0)
      EXPECT_NEAR(g0.rows[i][1], t_sensed, 1e-9) << i;
    else
      EXPECT_TRUE(std::isnan(g0.rows[i][1])) << i;
    EXPECT_NEAR(g0.rows[i][2], 2 * t_sensed, 1e-9) << i;
  }
  // The copy made at step 5 records from then on; the removed robot's
  // samples up to its removal are kept.
  const Csv copy = ReadCsv(dir / "out/graphs/bot#3/g.csv");
  EXPECT_GE(copy.rows.size(), 14u);
  EXPECT_LE(copy.rows.size(), 16u);
  const Csv removed = ReadCsv(dir / "out/graphs/bot#2/g.csv");
  EXPECT_GE(removed.rows.size(), 10u);
  EXPECT_LE(removed.rows.size(), 12u);
  // The distance to the wall shrinks by 0.02 m a step.
  const Csv gap = ReadCsv(dir / "out/graphs/clearance.csv");
  ASSERT_EQ(gap.rows.size(), 21u);
  for (size_t i = 1; i < gap.rows.size(); ++i)
    EXPECT_NEAR(gap.rows[i - 1][1] - gap.rows[i][1], 0.02, 1e-6) << i;
}

// A robot removed at run time that a distance object and a collection name
// (and whose joint another robot's joint follows): the run goes on, the
// distance finds nothing from then on, the collection lists the others,
// the follower stays where it was (the run stopped with "matches no
// object" at the removal's step).
TEST(GraphsRunTest, WhatNamesARemovedRobotGoesOnWithoutIt) {
  const fs::path dir =
      BotWorld("removed", "",
               "  - {model: follower.yaml, position: [5, 5]}\n"
               "obstacles:\n"
               "  - {name: wall, shape: box, size: [0.1, 20, 1], position: [10, 0, 0.5]}\n"
               "objects:\n"
               "  - {name: gap, type: distance, between: [/bot#2, /wall]}\n"
               "  - {name: bots, type: collection, trees: [/bot#1, /bot#2]}\n"
               "  - {name: clearance, type: graph, streams: [\"distance /gap\"]}\n",
               "function sysCall_sensing()\n"
               "  if sim.getObjectName(self) ~= 'bot#0' then return end\n"
               "  local step = math.floor(sim.getSimulationTime() * 10 + 0.5)\n"
               "  if step == 10 then sim.removeModel(sim.getObject('/bot#2')) end\n"
               "  if step == 12 then\n"
               "    print('collection', #sim.getCollectionObjects(sim.getObject('/bots')))\n"
               "    print('follower', sim.getJointPosition(sim.getObject('/follower#3/fj')))\n"
               "  end\n"
               "end\n");
  std::ofstream(dir / "follower.yaml")
      << "model: follower\nobjects: {name: body, type: dummy, children: [{name: fj, type: joint, "
         "master: \"/bot#2/wheel\"}]}\n";
  const auto r = RunWorld(dir, 20);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("[bot#0] collection\t2"), std::string::npos)
      << "bot#1's body and wheel: " << r.output;
  const Csv gap = ReadCsv(dir / "out/graphs/clearance.csv");
  ASSERT_EQ(gap.rows.size(), 21u);
  EXPECT_TRUE(std::isfinite(gap.rows[9][1])) << "bot#2 is there until step 10";
  EXPECT_TRUE(std::isnan(gap.rows[20][1])) << "then the distance finds nothing (no reading)";
  // The follower followed the wheel (0.5 rad/s) until the removal, then stays.
  const size_t at = r.output.find("[bot#0] follower\t");
  ASSERT_NE(at, std::string::npos) << r.output;
  const double q = std::stod(r.output.substr(at + 17));
  EXPECT_GT(q, 0.3) << r.output;
  EXPECT_LT(q, 0.6) << r.output;
}

// A proximity stream holds the sensor's reading of the step (what the
// script read in its sensing), nan when nothing is in range (the copies
// face random headings: some rays meet the wall, some do not).
TEST(GraphsRunTest, ProximityStreamHoldsTheSensorsReading) {
  const fs::path dir = BotWorld(
      "proximity",
      "    - {name: front, type: proximity_sensor, range: 20, orientation_deg: [0, 90, 0]}\n"
      "    - {name: g, type: graph, streams: [\"proximity :/front\"]}\n",
      "obstacles:\n"
      "  - {name: wall, shape: box, size: [0.1, 20, 1], position: [10, 0, 0.5]}\n",
      "function sysCall_sensing()\n"
      "  local r, d = sim.readProximitySensor(sim.getObject('./front'))\n"
      "  sim.recordMetric('front', r == 1 and d or -1)\n"
      "end\n");
  const auto r = RunWorld(dir, 10);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  int compared = 0;
  for (const auto& m : swarmsim::testing::ReadMetricsCsv(dir / "out/metrics.csv")) {
    if (m.metric != "front") continue;
    const Csv g = ReadCsv(dir / "out/graphs" / m.robot / "g.csv");
    ASSERT_EQ(g.rows.size(), 11u);
    const double sampled = g.rows.at(m.step + 1)[1];
    if (m.value < 0)
      EXPECT_TRUE(std::isnan(sampled)) << m.robot << " step " << m.step;
    else
      EXPECT_NEAR(m.value, sampled, 1e-8) << m.robot << " step " << m.step;  // 10 digits
    ++compared;
  }
  EXPECT_EQ(compared, 30);
}

// A force stream holds the force sensor's reading: a 2 kg load hanging
// from it pulls with its weight; a velocity stream the falling-free load's.
TEST(GraphsRunTest, ForceStreamHoldsTheLoadsWeight) {
  const fs::path dir = FreshTempDir("swarmsim_graphs", "force");
  fs::create_directories(dir);
  std::ofstream(dir / "hanger.yaml")
      << "model: hanger\n"
         "objects:\n"
         "  {type: shape, shape: box, size: [0.2, 0.2, 0.05], children: [\n"
         "    {name: hook, type: force_sensor, position: [0, 0, -0.05], children: [\n"
         "      {name: load, type: shape, shape: sphere, radius: 0.05, dynamic: true, mass: 2,\n"
         "       position: [0, 0, -0.25]}]},\n"
         "    {name: g, type: graph, streams: [\"f = force :/hook\", \"speed = velocity :/load "
         "norm\"]}]}\n";
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: ode, time_step: 0.01, physics_substeps: 2}\n"
         "models: [{model: hanger.yaml, position: [0, 0, 2]}]\n";
  const auto r = RunWorld(dir, 50);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Csv g = ReadCsv(dir / "out/graphs/hanger#0/g.csv");
  ASSERT_EQ(g.header, (std::vector<std::string>{"time", "f.x", "f.y", "f.z", "speed"}));
  ASSERT_EQ(g.rows.size(), 51u);
  EXPECT_TRUE(std::isnan(g.rows[0][3]));  // no reading before the first physics step
  const std::vector<double>& last = g.rows.back();
  EXPECT_NEAR(std::hypot(last[1], last[2], last[3]), 2 * 9.81, 0.2);
  EXPECT_NEAR(last[4], 0, 1e-3);  // held still
}

TEST(GraphsRunTest, SameFilesAndHashAtOneAndTwoThreads) {
  const fs::path dir = BotWorld(
      "threads",
      "    - {name: trace, type: graph, streams: [\"position :\", \"joint :/wheel\", \"orientation "
      ": yaw\"]}\n");
  std::string hashes[2];
  for (int t = 0; t < 2; ++t) {
    const auto r = RunProgram("run " + (dir / "world.yaml").string() +
                              " --steps 30 --hash --quiet --threads " + std::to_string(t + 1) +
                              " --out " + (dir / ("out" + std::to_string(t))).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    hashes[t] = HashOf(r.output);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  for (int k = 0; k < 3; ++k) {
    const std::string file = "graphs/bot#" + std::to_string(k) + "/trace.csv";
    const std::string one = ReadFile(dir / "out0" / file);
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, ReadFile(dir / "out1" / file)) << file;
  }
}

TEST(GraphsRunTest, CsvIsWrittenWithoutGnuplot) {
  const fs::path dir =
      BotWorld("nognuplot", "    - {name: trace, type: graph, streams: [\"position : x\"]}\n");
  // No gnuplot on the PATH (the program is named by its full path).
  const auto r = swarmsim::testing::RunCommand(
      "PATH=/nonexistent " SWARMSIM_BINARY " run " + (dir / "world.yaml").string() +
      " --steps 5 --quiet --out " + (dir / "out").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: graphs: gnuplot not found"), std::string::npos) << r.output;
  EXPECT_EQ(ReadCsv(dir / "out/graphs/bot#0/trace.csv").rows.size(), 6u);
  EXPECT_FALSE(fs::exists(dir / "out/graphs/bot#0/trace.png"));
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(dir / "out/summary.json"));
  int pngs = 0, csvs = 0;
  for (const auto& o : summary.at("outputs")) {
    const std::string path = o.at("path");
    pngs += path.ends_with(".png");
    csvs += path.ends_with(".csv");
  }
  EXPECT_EQ(pngs, 0);
  EXPECT_EQ(csvs, 3);
}

// A graph with nothing to draw (a script stream no script sets) still gets
// its CSV (nan) and a PNG saying so; the other graphs are drawn too (one
// gnuplot script holds them all: an empty plot must not stop it).
TEST(GraphsRunTest, GraphsWithoutDataGetAnEmptyPlotAndTheOthersTheirs) {
  const fs::path dir =
      BotWorld("nodata",
               "    - {name: a, type: graph, streams: [\"script never\"]}\n"
               "    - {name: b, type: graph, kind: xyz, streams: [\"x = script\", \"y = script\", "
               "\"z = script\"]}\n"
               "    - {name: c, type: graph, streams: [\"position : x\"]}\n");
  const auto r = RunWorld(dir, 3);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  for (int k = 0; k < 3; ++k)
    for (const char* name : {"a", "b", "c"})
      EXPECT_TRUE(
          IsPng(dir / "out/graphs" / ("bot#" + std::to_string(k)) / (name + std::string(".png"))))
          << k << name;
  for (const auto& row : ReadCsv(dir / "out/graphs/bot#0/a.csv").rows)
    EXPECT_TRUE(std::isnan(row[1]));
}

// 201 copies with a graph each: every CSV, the first 200 PNGs, a warning
// and a note in summary.json for the rest.
TEST(GraphsRunTest, PngsPastTheCapAreLeftOutWithANote) {
  const fs::path dir = FreshTempDir("swarmsim_graphs", "cap");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml")
      << "simulation: {physics: kinematic, time_step: 0.1}\n"
         "models:\n"
         "  - {model: dot.yaml, count: 201, distribute: {region: {min: [-20, -20], max: [20, "
         "20]}}}\n";
  std::ofstream(dir / "dot.yaml") << "model: dot\nobjects: {name: body, type: dummy, children: [\n"
                                     "  {name: g, type: graph, streams: [\"position : x\"]}]}\n";
  const auto r = RunWorld(dir, 2);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("PNGs drawn for the first 200 graphs only; 1 more"), std::string::npos)
      << r.output;
  EXPECT_TRUE(IsPng(dir / "out/graphs/dot#199/g.png"));
  EXPECT_FALSE(fs::exists(dir / "out/graphs/dot#200/g.png"));
  EXPECT_TRUE(fs::exists(dir / "out/graphs/dot#200/g.csv"));
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(dir / "out/summary.json"));
  int csv = 0, png = 0, notes = 0;
  for (const auto& o : summary.at("outputs")) {
    const std::string path = o.at("path");
    csv += path.ends_with(".csv");
    png += path.ends_with(".png");
    notes += o.at("kind") == "note";
  }
  EXPECT_EQ(csv, 201);
  EXPECT_EQ(png, 200);
  EXPECT_EQ(notes, 1);
}

TEST(GraphsRunTest, CyclicBufferKeepsTheLastSamples) {
  const fs::path dir = BotWorld("cyclic",
                                "    - {name: last, type: graph, streams: [\"joint :/wheel\"], "
                                "buffer: 5, cyclic: true, every: 2}\n"
                                "    - {name: first, type: graph, streams: [\"joint :/wheel\"], "
                                "buffer: 5}\n");
  const auto r = RunWorld(dir, 20);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Csv last = ReadCsv(dir / "out/graphs/bot#0/last.csv");
  ASSERT_EQ(last.rows.size(), 5u);
  for (size_t i = 0; i < 5; ++i)  // steps 12, 14, ..., 20
    EXPECT_NEAR(last.rows[i][0], 1.2 + 0.2 * static_cast<double>(i), 1e-9);
  const Csv first = ReadCsv(dir / "out/graphs/bot#0/first.csv");
  ASSERT_EQ(first.rows.size(), 5u);
  EXPECT_NEAR(first.rows.back()[0], 0.4, 1e-9);
  const nlohmann::json summary = nlohmann::json::parse(ReadFile(dir / "out/summary.json"));
  bool noted = false;
  for (const auto& o : summary.at("outputs"))
    if (o.at("path") == "graphs/bot#0/first.csv")
      noted = o.at("description").get<std::string>().find("buffer full") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A bad graph is a load error at its file:line:col, exit 2.
void ExpectLoadError(const std::string& name, const std::string& graph, const std::string& where,
                     const std::string& message) {
  const fs::path dir = BotWorld(name, graph);
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(where), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
}

TEST(GraphsRunTest, BadStreamsAreLoadErrorsAtTheirLine) {
  ExpectLoadError("kind", "    - {name: g, type: graph, streams: [\"positon : x\"]}\n",
                  "bot.yaml:11:", "unknown stream kind 'positon'; did you mean 'position'?");
  ExpectLoadError("path", "    - {name: g, type: graph, streams: [\"joint :/wheal\"]}\n",
                  "bot.yaml:11:", "':/wheal' matches no object; did you mean ':/wheel'?");
  ExpectLoadError("below", "    - {name: g, type: graph, streams: [\"joint ./wheel\"]}\n",
                  "bot.yaml:11:", "did you mean ':/wheel', in the graph's model?");
  ExpectLoadError("root", "    - {name: g, type: graph, streams: [\"position :/body z\"]}\n",
                  "bot.yaml:11:", "the model's root is ':' itself, named after the copy");
  ExpectLoadError("type", "    - {name: g, type: graph, streams: [\"joint :\"]}\n",
                  "bot.yaml:11:", "':' is a shape, not a joint");
  ExpectLoadError("component", "    - {name: g, type: graph, streams: [\"position : w\"]}\n",
                  "bot.yaml:11:", "'position' has no component 'w'");
  ExpectLoadError("nopath", "    - {name: g, type: graph, streams: [\"velocity\"]}\n",
                  "bot.yaml:11:", "'velocity' needs an object path");
  ExpectLoadError("xy", "    - {name: g, type: graph, kind: xy, streams: [\"position :\"]}\n",
                  "bot.yaml:11:", "takes 2 streams");
  ExpectLoadError("twice",
                  "    - {name: g, type: graph, streams: [\"script a\", \"a = script\"]}\n",
                  "bot.yaml:11:", "two streams are named 'a'");
}

TEST(GraphsRunTest, SettingANonScriptStreamIsAScriptError) {
  const fs::path dir = BotWorld(
      "setbad", "    - {name: g, type: graph, streams: [\"x = position : x\", \"script s\"]}\n", "",
      "function sysCall_sensing()\n"
      "  sim.setGraphStreamValue(sim.getObject('./g'), 'x', 1)\n"
      "end\n");
  const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --steps 2 --quiet");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("bot.lua:11:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("stream 'x' of graph /bot#0/g is not a script stream"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("its script streams: 's'"), std::string::npos) << r.output;
}

}  // namespace

namespace {

// The example worlds' graphs show what the worlds do.
TEST(GraphsExamplesTest, ArmGraphsShowTheBoxCarriedAndDropped) {
  const fs::path out = FreshTempDir("swarmsim_graphs", "arm");
  const auto r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                            "/worlds/arm_pick_and_place.yaml --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The box is lifted while the task says it is carried, and lands on the
  // table (its top at 0.4 m) after the release.
  const Csv box = ReadCsv(out / "graphs/box_height.csv");
  const Csv task = ReadCsv(out / "graphs/ur5#0/task.csv");
  ASSERT_EQ(box.rows.size(), 501u);
  ASSERT_EQ(task.rows.size(), box.rows.size());
  double highest = 0, carried_time = 0;
  for (size_t i = 0; i < box.rows.size(); ++i) {
    highest = std::max(highest, box.rows[i][1]);
    if (task.rows[i][2] == 1) carried_time += 0.02;
  }
  EXPECT_GT(highest, 0.425 + 0.1);
  EXPECT_NEAR(box.rows.back()[1], 0.425, 0.005);
  EXPECT_NEAR(carried_time, 4, 0.1);  // grasp at 3 s, release at 7 s
  EXPECT_EQ(task.rows.back()[1], 7);  // past the last of 6 segments
  EXPECT_EQ(ReadCsv(out / "graphs/ur5#0/joints.csv").header.size(), 7u);
  EXPECT_EQ(ReadCsv(out / "graphs/ur5#0/tip_path.csv").header,
            (std::vector<std::string>{"time", "tip.x", "tip.y", "tip.z"}));
  for (const char* png : {"box_height.png", "ur5#0/task.png", "ur5#0/tip_path.png"})
    EXPECT_TRUE(IsPng(out / "graphs" / png)) << png;
}

TEST(GraphsExamplesTest, HexapodGraphsShowItStandingAndWalking) {
  const fs::path out = FreshTempDir("swarmsim_graphs", "hexapod");
  const auto r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                            "/worlds/hexapod.yaml --steps 500 --quiet --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Csv body = ReadCsv(out / "graphs/body.csv");
  ASSERT_EQ(body.header, (std::vector<std::string>{"time", "height", "clearance"}));
  ASSERT_EQ(body.rows.size(), 501u);
  for (const auto& row : body.rows) EXPECT_GT(row[1], 0.03);  // standing all along
  // The track goes along +x; the knee swings through its gait.
  const Csv track = ReadCsv(out / "graphs/track.csv");
  EXPECT_GT(track.rows.back()[1] - track.rows.front()[1], 0.2);
  const Csv leg = ReadCsv(out / "graphs/leg0.csv");
  double knee_lo = 10, knee_hi = -10;
  for (const auto& row : leg.rows)
    knee_lo = std::min(knee_lo, row[3]), knee_hi = std::max(knee_hi, row[3]);
  EXPECT_GT(knee_hi - knee_lo, 0.3);
}

TEST(GraphsExamplesTest, ThreadedArmsHaveOneGraphPerCopyEqualAtOneAndTwoThreads) {
  const fs::path out = FreshTempDir("swarmsim_graphs", "arms");
  for (int t = 1; t <= 2; ++t) {
    const auto r = RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                              "/worlds/threaded_arms.yaml --steps 200 --quiet --threads " +
                              std::to_string(t) + " --out " + (out / std::to_string(t)).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  for (int k = 0; k < 16; ++k) {
    const std::string file = "graphs/gripper_arm#" + std::to_string(k) + "/joints.csv";
    const std::string one = ReadFile(out / "1" / file);
    ASSERT_FALSE(one.empty()) << file;
    EXPECT_EQ(one, ReadFile(out / "2" / file)) << file;
  }
  // The shoulder swings to 90 degrees and back.
  double widest = 0;
  for (const auto& row : ReadCsv(out / "1/graphs/gripper_arm#0/joints.csv").rows)
    widest = std::max(widest, row[1]);
  EXPECT_NEAR(widest, M_PI / 2, 0.01);
}

}  // namespace
