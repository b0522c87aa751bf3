// Mills and cuttables in world files (modules/mill): the keys and their
// mistakes (file:line:col), a drill whose removed volume a user can work
// out by hand, copies and scaled copies with blocks of their own, the map
// cut, the scripts' calls, the thread count, and the docs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/mill/rows.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using mill::CuttableRow;
using mill::MillRow;

constexpr double kPi = 3.141592653589793;

using MillTest = testing::WorldDirTest;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST_F(MillTest, BadKeysAreFileLineColumnErrors) {
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: cone\n  angle_deg: 90\n"),
                  "thing.yaml:5:14: 'angle_deg' must be above 0 and below 90 degrees (got 90)");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: cone\n  angle_deg: -5\n"), "thing.yaml:5:14:");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: disc\n  angle_deg: .nan\n"), "thing.yaml:5:14:");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: disc\n  angle_deg: 91\n"), "up to 90 degrees");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: cone\n  radius: 0.1\n"),
                  "thing.yaml:5:3: 'radius' applies to cylinder mills only (this is a cone)");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: cylnder\n"), "did you mean 'cylinder'?");
  EXPECT_CONTAINS(ErrorOf("mill", "  range: -1\n"), "thing.yaml:4:10:");
  EXPECT_CONTAINS(ErrorOf("mill", "  volume: box\n  width: 0\n"), "'width' must be a positive");
  EXPECT_CONTAINS(ErrorOf("cuttable", "  size: [1, 1, 1]\n  resolution: 0.0001\n"),
                  "thing.yaml:5:15: the block would have 10000 x 10000 x 10000 = 1000000000000 "
                  "voxels, more than 50000000");
  EXPECT_CONTAINS(ErrorOf("cuttable", "  size: [1, -1, 1]\n"), "thing.yaml:4:");
  EXPECT_EQ(ErrorOf("mill", "  volume: disc\n  angle_deg: 90\n  thickness: 0.01\n"), "(no error)");
}

// A drill: a cylinder mill of radius r on a slide pushed down into a block
// takes pi r^2 x depth, within the voxels' error, and exactly the voxels
// whose centres it passed over (counted here by hand).
const char* kDrill =
    "model: drill\n"
    "parameters: {depth: 0.19}\n"
    "objects:\n"
    "  type: dummy\n"
    "  script: drill.lua\n"
    "  children:\n"
    "    - name: slide\n"
    "      type: joint\n"
    "      joint: prismatic\n"
    "      mode: position\n"
    "      max_velocity: 0.01\n"
    "      orientation_deg: [180, 0, 0]\n"  // the slide's z (and the mill's) points down
    "      children:\n"
    "        - {name: bit, type: mill, volume: cylinder, radius: 0.02, range: 0.01}\n";
const char* kDrillScript =
    "function sysCall_init()\n"
    "  sim.setJointTargetPosition(sim.getObject('./slide'), sim.getParam('depth'))\n"
    "end\n"
    "function sysCall_sensing()\n"
    "  local step, total = sim.readMill(sim.getObject('./bit'))\n"
    "  local left, start, volume = sim.readCuttable(sim.getObject('/block'))\n"
    "  sim.recordMetric('total', total)\n"
    "  sim.recordMetric('left', left)\n"
    "  sim.recordMetric('start', start)\n"
    "end\n";

TEST_F(MillTest, ACylinderDrillRemovesPiRSquaredTimesDepth) {
  Write("drill.yaml", kDrill);
  Write("drill.lua", kDrillScript);
  // The block's top at z = 0.2; the bit's tip starts at 0.29 and ends at
  // 0.1 (0.19 m of travel): 0.1 m deep.
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "objects: [{name: block, type: cuttable, size: [0.2, 0.2, 0.2], resolution: 0.0025,\n"
      "           position: [0, 0, 0.1]}]\n"
      "models: [{model: drill.yaml, position: [0, 0, 0.3]}]\n");
  World& world = *w.world;
  const CuttableRow& block = RowOf<CuttableRow>(world, "/block");
  EXPECT_EQ(block.voxel_count(), 80 * 80 * 80);
  EXPECT_EQ(block.remaining, block.voxel_count());
  for (int i = 0; i < 250; ++i) world.Step();
  const MillRow& bit = RowOf<MillRow>(world, "/drill#0/bit");
  // Voxel centres (i + 1/2) h within r of the axis, times 40 layers of h.
  const double h = 0.0025;
  int64_t disc = 0;
  for (int i = -8; i < 8; ++i)
    for (int j = -8; j < 8; ++j)
      disc += ((i + 0.5) * h) * ((i + 0.5) * h) + ((j + 0.5) * h) * ((j + 0.5) * h) <= 0.02 * 0.02;
  EXPECT_EQ(block.voxel_count() - block.remaining, disc * 40);
  EXPECT_NEAR(bit.removed_total, static_cast<double>(disc * 40) * h * h * h, 1e-12);
  // pi r^2 depth: the counted centres' squares lie within r + h / sqrt(2) of
  // the axis, and every square within r - h / sqrt(2) is counted.
  const double d = h / std::sqrt(2.0);
  EXPECT_GT(bit.removed_total, kPi * (0.02 - d) * (0.02 - d) * 0.1);
  EXPECT_LT(bit.removed_total, kPi * (0.02 + d) * (0.02 + d) * 0.1);
  EXPECT_NEAR(bit.removed_total, kPi * 0.02 * 0.02 * 0.1, 0.04 * kPi * 0.02 * 0.02 * 0.1);
  // The scripts read the same; metrics.csv has the volume per step and what is left.
  std::map<std::string, double> last;
  double summed = 0;
  for (const MetricSample& m : world.TakeMetrics()) {
    last[m.name] = m.value;
    if (m.name == "bit.removed") summed += m.value;
  }
  EXPECT_NEAR(summed, bit.removed_total, 1e-12);
  EXPECT_NEAR(last["total"], bit.removed_total, 1e-12);
  EXPECT_EQ(last["left"], static_cast<double>(block.remaining));
  EXPECT_EQ(last["start"], 512000);
  EXPECT_NEAR(last["block.remaining"], 0.008 - bit.removed_total, 1e-12);
  EXPECT_EQ(last["bit.removed"], 0);  // arrived: nothing left under the bit
  // The run's output: mill.csv.
  world.WriteOutputs(dir_);
  std::ifstream csv(dir_ / "mill.csv");
  std::stringstream text;
  text << csv.rdbuf();
  EXPECT_CONTAINS(text.str(), "object,type,removed_m3,voxels,voxels_left,volume_left_m3\n");
  EXPECT_CONTAINS(text.str(), "/block,cuttable,");
  EXPECT_CONTAINS(text.str(), ",512000," + std::to_string(block.remaining) + ",");
}

// Copies (placed, scaled, and made at run time) each get a full block of
// their own; a scaled copy keeps its grid, so its voxels scale with it.
TEST_F(MillTest, CopiesGetFreshBlocksAndScaleWithTheirModel) {
  Write("crate.yaml",
        "model: crate\n"
        "objects:\n"
        "  type: dummy\n"
        "  script: crate.lua\n"
        "  children:\n"
        "    - {name: stock, type: cuttable, size: [0.1, 0.1, 0.1], resolution: 0.01}\n"
        // A 0.1 x 0.1 slab 0.02 thick through the stock's top: 2 layers of 100 voxels.
        "    - {name: cutter, type: mill, volume: box, width: 0.12, height: 0.12, range: 0.02,\n"
        "       position: [0, 0, 0.03], orientation_deg: [180, 0, 0]}\n");
  Write("crate.lua",
        "local n = 0\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  if n == 3 and sim.getObject('.') == sim.getObject('/crate#0') then\n"
        "    sim.copyModel(sim.getObject('.'), {2, 0, 0})\n"
        "  end\n"
        "end\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "models:\n"
      "  - {model: crate.yaml, position: [0, 0, 1]}\n"
      "  - {model: crate.yaml, position: [1, 0, 1], scale: 2}\n");
  World& world = *w.world;
  for (int i = 0; i < 5; ++i) world.Step();
  const CuttableRow& plain = RowOf<CuttableRow>(world, "/crate#0/stock");
  const CuttableRow& scaled = RowOf<CuttableRow>(world, "/crate#1/stock");
  const CuttableRow& copy = RowOf<CuttableRow>(world, "/crate#2/stock");
  EXPECT_EQ(plain.remaining, 800);
  EXPECT_EQ(scaled.remaining, 800);
  EXPECT_EQ(copy.remaining, 800);  // copied cut: a full block, cut afresh by its own mill
  EXPECT_DOUBLE_EQ(scaled.size.x, 0.2);
  EXPECT_NEAR(RowOf<MillRow>(world, "/crate#1/cutter").removed_total,
              8 * RowOf<MillRow>(world, "/crate#0/cutter").removed_total, 1e-12);
  EXPECT_NEAR(RowOf<MillRow>(world, "/crate#2/cutter").removed_total, 200 * 1e-6, 1e-12);
  // Equal cuts, equal digests; the hash sees them.
  EXPECT_EQ(plain.digest, copy.digest);
  EXPECT_NE(plain.digest, 0u);
}

// Scripts switch their own mills only; a disabled mill removes nothing.
TEST_F(MillTest, ScriptsSwitchTheirOwnMills) {
  std::string drill = kDrill;
  drill.replace(drill.find("range: 0.01}"), 12, "range: 0.01, enabled: false}");
  Write("drill.yaml", drill);
  Write("drill.lua",
        "local n = 0\n"
        "function sysCall_init()\n"
        "  sim.setJointTargetPosition(sim.getObject('./slide'), 0.19)\n"
        "end\n"
        "function sysCall_actuation()\n"
        "  n = n + 1\n"
        "  if n == 150 then sim.setMillEnabled(sim.getObject('./bit'), true) end\n"
        "  if n == 160 and sim.getObject('.') == sim.getObject('/drill#1') then\n"
        "    sim.setMillEnabled(sim.getObject('/drill#0/bit'), false)\n"
        "  end\n"
        "end\n");
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, time_step: 0.1}\n"
      "objects: [{name: block, type: cuttable, size: [0.2, 0.2, 0.2], resolution: 0.005,\n"
      "           position: [0, 0, 0.1]}]\n"
      "models: [{model: drill.yaml, position: [0, 0, 0.3]},\n"
      "         {model: drill.yaml, position: [3, 0, 0.3]}]\n");
  World& world = *w.world;
  for (int i = 0; i < 149; ++i) world.Step();
  EXPECT_EQ(RowOf<MillRow>(world, "/drill#0/bit").removed_total, 0);
  EXPECT_EQ(RowOf<CuttableRow>(world, "/block").remaining, 40 * 40 * 40);
  for (int i = 0; i < 5; ++i) world.Step();
  EXPECT_GT(RowOf<MillRow>(world, "/drill#0/bit").removed_total, 0);
  try {
    for (int i = 0; i < 10; ++i) world.Step();
    ADD_FAILURE() << "drill#1 switched drill#0's mill";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(),
                    "a robot's script may switch only its own mills ('/drill#0/slide/bit'");
  }
}

// sim.readMill on what is not a mill is an error naming the object.
TEST_F(MillTest, ReadingWhatIsNotAMillIsAnError) {
  Write("probe.yaml", "model: probe\nobjects: {type: dummy, script: probe.lua}\n");
  Write("probe.lua", "function sysCall_init() sim.readMill(sim.getObject('/block')) end\n");
  try {
    Load(
        "simulation: {physics: kinematic}\n"
        "objects: [{name: block, type: cuttable}]\n"
        "models: [{model: probe.yaml, position: [0, 0, 1]}]\n")
        .world->Start();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "sim.readMill: object /block is not a mill");
  }
}

// The example world: the blocks' voxels drop, every mill takes some, the
// mills' volumes add up to the block's loss, and the hash is the same at
// 1, 2 and 4 threads.
TEST_F(MillTest, MillingExampleIsIndependentOfThreadCount) {
  uint64_t hashes[3];
  const int threads[3] = {1, 2, 4};
  for (int t = 0; t < 3; ++t) {
    LoadOptions options;
    options.threads = threads[t];
    LoadedWorld w =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/milling.yaml", options, registry_);
    World& world = *w.world;
    world.set_log_sink([](std::string_view) {});
    for (int i = 0; i < 200; ++i) world.Step();
    hashes[t] = world.StateHash();
    const CuttableRow& block = RowOf<CuttableRow>(world, "/block");
    double milled = 0;
    for (int r = 0; r < 4; ++r) {
      const double total =
          RowOf<MillRow>(world, "/millbot#" + std::to_string(r) + "/mill").removed_total;
      EXPECT_GT(total, 1e-4);
      milled += total;
    }
    EXPECT_LT(block.remaining, block.voxel_count() * 95 / 100);
    EXPECT_NEAR(milled,
                static_cast<double>(block.voxel_count() - block.remaining) * 0.005 * 0.005 * 0.005,
                1e-12);
  }
  EXPECT_EQ(hashes[1], hashes[0]);
  EXPECT_EQ(hashes[2], hashes[0]);
}

// Mills cut the environment map: the scene gets a new map without the
// voxels the drill passed over, and the mill counts them.
TEST_F(MillTest, MillsCutTheEnvironmentMap) {
  Write("drill.yaml", kDrill);
  Write("drill.lua",
        "function sysCall_init()\n"
        "  sim.setJointTargetPosition(sim.getObject('./slide'), 0.19)\nend\n");
  const auto run = [&](int threads, bool with_map) {
    LoadedWorld w = Load(
        "simulation: {physics: kinematic, time_step: 0.1}\n"
        "models: [{model: drill.yaml, position: [0, 0, 0.3]}]\n",
        threads);
    // The map: a 0.32 m octree leaf and eight 0.04 m ones beside it, 0.01 m voxels.
    auto map = std::make_shared<EnvironmentMap>();
    map->resolution = 0.01;
    map->boxes.push_back({{-0.16, -0.16, -0.12}, {0.16, 0.16, 0.2}});
    for (int i = 0; i < 8; ++i)
      map->boxes.push_back({{0.16 + 0.04 * i, 0, 0}, {0.2 + 0.04 * i, 0.04, 0.04}});
    map->lo = {-0.16, -0.16, -0.12};
    map->hi = {0.48, 0.16, 0.2};
    if (with_map) w.world->scene().set_environment(map);
    for (int i = 0; i < 250; ++i) w.world->Step();
    if (with_map)
      EXPECT_NE(w.world->scene().environment(), map.get());  // a new map
    else
      EXPECT_EQ(w.world->scene().environment(), nullptr);
    if (with_map) {
      const EnvironmentMap& now = *w.world->scene().environment();
      double volume = 0;
      for (const EnvironmentBox& b : now.boxes)
        volume += (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
      const double milled = RowOf<MillRow>(*w.world, "/drill#0/bit").removed_total;
      // 0.1 m deep (from z = 0.2 down to 0.1), within the voxels' error.
      EXPECT_NEAR(milled, kPi * 0.02 * 0.02 * 0.1, 0.1 * kPi * 0.02 * 0.02 * 0.1);
      EXPECT_NEAR(volume, 0.32 * 0.32 * 0.32 + 8 * 0.04 * 0.04 * 0.04 - milled, 1e-9);
      EXPECT_EQ(now.boxes.back().lo, map->boxes.back().lo);  // untouched boxes keep their order
      EXPECT_EQ(now.resolution, 0.01);
    }
    return w.world->StateHash();
  };
  const uint64_t one = run(1, true);
  EXPECT_EQ(run(2, true), one);
  EXPECT_NE(run(1, false), one);
}

}  // namespace
}  // namespace swarmsim
