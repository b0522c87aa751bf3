// Recording a run (swarm/record/writer.cc): a recorded run reads back as the
// run was: every recorded object's pose, LED colours, the paint layer and the
// metric samples, step by step, also through robots copied and removed at run
// time and from a keyframe.
#include "swarm/record/writer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <tuple>

#include "framework/error.h"
#include "framework/floor_layer.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/blobs/leds.h"
#include "modules/builtin.h"
#include "modules/proximity/proximity_sensor.h"
#include "swarm/loader/world_loader.h"
#include "swarm/record/format.h"
#include "swarm/record/reader.h"
#include "tests/framework/error_of.h"
#include "tests/swarm/run_program.h"

namespace swarmsim::record {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("recording_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The recorded objects' slots in id order, as FORMAT.md defines them: live
// robots in index order, each its root then its shapes, LEDs and proximity
// sensors in hierarchy order; then those outside robots in slot order.
std::vector<uint32_t> RecordedSlots(const Scene& scene) {
  ObjectType led{};
  const bool has_leds = scene.FindType(kLedTypeName, &led);
  const auto recorded = [&](uint32_t slot) {
    const ObjectType t = scene.type_at(slot);
    return t == ObjectType::kShape || proximity::IsSensorAt(scene, slot) || (has_leds && t == led);
  };
  std::vector<uint32_t> slots;
  for (const ModelInstance& robot : scene.instances()) {
    if (!robot.alive) continue;
    const uint32_t root = scene.SlotOf(robot.root);
    for (const uint32_t slot : robot.objects)
      if (slot == root || recorded(slot)) slots.push_back(slot);
  }
  for (uint32_t slot = 0; slot < scene.slot_count(); ++slot)
    if (scene.alive_at(slot) && scene.instance_of_at(slot) < 0 && recorded(slot))
      slots.push_back(slot);
  return slots;
}

struct Loaded {
  ModuleRegistry registry;
  LoadedWorld loaded;
  RunRecorder* recorder = nullptr;
};

std::unique_ptr<Loaded> LoadRecorded(
    const std::string& world, int robots, const fs::path& out, RecordSettings settings = {},
    std::vector<std::pair<std::string, std::string>> overrides = {}) {
  auto l = std::make_unique<Loaded>();
  RegisterBuiltinModules(&l->registry);
  LoadOptions options;
  options.overrides = std::move(overrides);
  options.overrides.emplace_back("robots", std::to_string(robots));
  const int threads = 2;
  options.threads = threads;
  l->loaded = LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/" + world, options, l->registry);
  l->loaded.world->set_log_sink([](std::string_view) {});
  settings.out_dir = out;
  settings.world_file = world;
  l->recorder = AddRecorder(l->loaded.world.get(), settings);
  return l;
}

// Starts the world, runs `steps` steps and completes the recording.
World& RunRecorded(Loaded* l, int steps) {
  World& world = *l->loaded.world;
  world.Start();
  for (int i = 0; i < steps; ++i) world.Step();
  l->recorder->Finish(steps, "ok", "");
  return world;
}

// The world poses the run had, by recorded id, after each step (0: the start).
using PoseTable = std::vector<std::vector<Pose>>;

void ExpectNear(const Pose& recorded, const Pose& actual, const std::string& what) {
  // Positions in 0.1 mm, quaternions in 1/32767: the world pose of a robot's
  // part also carries its root's rounding.
  EXPECT_LT((recorded.p - actual.p).Norm(), 2e-4) << what;
  const double dot = std::abs(recorded.q.w * actual.q.w + recorded.q.x * actual.q.x +
                              recorded.q.y * actual.q.y + recorded.q.z * actual.q.z);
  EXPECT_GT(dot, 1 - 1e-7) << what;
}

// The samples scripts record (sim.recordMetric, stamped with the step their
// callback ran in) are in the recording with the observers', each once,
// whether or not the runner takes them after every step.
TEST(RecordingTest, ScriptMetricsAreRecordedOnceEach) {
  for (const bool taken_every_step : {true, false}) {
    const fs::path out = TempDir(taken_every_step ? "script_metrics_taken" : "script_metrics");
    Loaded l;
    RegisterBuiltinModules(&l.registry);
    LoadOptions options;
    options.threads = 2;
    l.loaded =
        LoadWorld(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/milling.yaml", options, l.registry);
    l.loaded.world->set_log_sink([](std::string_view) {});
    RecordSettings settings;
    settings.out_dir = out;
    settings.world_file = "worlds/milling.yaml";
    l.recorder = AddRecorder(l.loaded.world.get(), settings);
    World& world = *l.loaded.world;
    std::vector<MetricSample> run;
    world.Start();
    for (int i = 0; i < 12; ++i) {
      world.Step();
      if (taken_every_step)
        for (MetricSample& m : world.TakeMetrics()) run.push_back(std::move(m));
    }
    l.recorder->Finish(12, "ok", "");
    if (!taken_every_step) run = world.TakeMetrics();

    std::multiset<std::tuple<std::string, int, int64_t, double>> expected, recorded;
    for (const MetricSample& m : run) expected.emplace(m.name, m.instance, m.step, m.value);
    RecordingPlayer player(out);
    while (player.Next())
      for (const auto& s : player.samples())
        recorded.emplace(std::string(s.name), s.robot, s.step, s.value);
    EXPECT_EQ(recorded, expected) << "taken every step: " << taken_every_step;
    // Each robot's script recorded `milled` in every one of the 12 steps.
    size_t milled = 0;
    for (const auto& [name, robot, step, value] : recorded)
      milled += name == "milled" && robot >= 0;
    EXPECT_EQ(milled, 4u * 12u) << "taken every step: " << taken_every_step;
  }
}

TEST(RecordingTest, PosesAndMetricsReadBackAsTheRunHadThem) {
  const fs::path out = TempDir("poses");
  auto l = LoadRecorded("worlds/diffusion.yaml", 30, out);
  World& world = *l->loaded.world;
  PoseTable poses;
  std::vector<std::vector<MetricSample>> metrics;
  const auto snapshot = [&] {
    std::vector<Pose> row;
    for (const uint32_t slot : RecordedSlots(world.scene()))
      row.push_back(world.scene().world_pose_at(slot));
    poses.push_back(std::move(row));
    metrics.push_back(world.TakeMetrics());
  };
  world.Start();
  snapshot();
  for (int i = 0; i < 40; ++i) {
    world.Step();
    snapshot();
  }
  l->recorder->Finish(40, "ok", "");

  RecordingPlayer player(out);
  EXPECT_TRUE(player.info().ended);
  EXPECT_FALSE(player.info().truncated);
  EXPECT_EQ(player.info().step_records, 41);
  int64_t records = 0, samples = 0;
  while (player.Next()) {
    const int64_t step = player.step();
    ASSERT_EQ(step, records++);
    EXPECT_DOUBLE_EQ(player.time(), step * 0.1);
    ASSERT_EQ(player.object_count(), poses[step].size());
    for (uint32_t id = 0; id < player.object_count(); ++id)
      ExpectNear(player.world_pose(id), poses[step][id],
                 "step " + std::to_string(step) + " id " + std::to_string(id));
    // Metric samples: those the run recorded in that step, exactly.
    ASSERT_EQ(player.samples().size(), metrics[step].size()) << "step " << step;
    for (size_t i = 0; i < metrics[step].size(); ++i) {
      EXPECT_EQ(player.samples()[i].name, metrics[step][i].name);
      EXPECT_EQ(player.samples()[i].robot, metrics[step][i].instance);
      EXPECT_EQ(player.samples()[i].step, metrics[step][i].step);
      EXPECT_EQ(player.samples()[i].value, metrics[step][i].value);
      ++samples;
    }
  }
  EXPECT_EQ(records, 41);
  EXPECT_GT(samples, 0);  // mean_nearest_neighbor_distance every 10 steps
  // The robots moved: the recording is not the start repeated.
  EXPECT_GT((poses[40][0].p - poses[0][0].p).Norm(), 0.01);
  // The scene names the robots and their model.
  const nlohmann::json scene = nlohmann::json::parse(player.scene_json());
  ASSERT_EQ(scene["robots"].size(), 30u);
  EXPECT_EQ(scene["robots"][3]["name"], "footbot#3");
  EXPECT_EQ(scene["robots"][3]["model"], "footbot");
  EXPECT_EQ(scene["templates"].size(), 1u);  // 30 copies described once
  // The root first: the body cylinder, with its colour; then the wheels and the 24 sensors.
  const nlohmann::json& objects = scene["templates"][0]["objects"];
  ASSERT_EQ(objects.size(), 27u);
  EXPECT_EQ(objects[0]["type"], "shape");
  EXPECT_EQ(objects[0]["shape"], "cylinder");
  EXPECT_EQ(objects[0]["size"][0], 0.085);
  EXPECT_EQ(objects[0]["color"], nlohmann::json::parse("[0.2, 0.6, 0.2]"));
  EXPECT_EQ(objects[1]["name"], "leftWheel");
  EXPECT_EQ(objects[26]["type"], "proximity_sensor");
  EXPECT_EQ(objects[26]["range"], 0.1);
  EXPECT_EQ(objects[26]["parent"], 0);
  EXPECT_EQ(scene["robots"][3]["parameters"]["wheel_speed"], 0.05);
  fs::remove_all(out);
}

TEST(RecordingTest, SeekingFromAKeyframeGivesTheStateOfPlayingThrough) {
  const fs::path out = TempDir("seek");
  RecordSettings settings;
  settings.keyframe_every = 7;
  RunRecorded(LoadRecorded("worlds/diffusion.yaml", 12, out, settings).get(), 30);
  RecordingPlayer through(out), seek(out);
  int keyframes = 0;
  for (const ChunkInfo& c : through.info().chunks)
    keyframes += c.kind == static_cast<uint8_t>(ChunkKind::kKeyframe);
  EXPECT_EQ(keyframes, 5);  // records 0, 7, 14, 21, 28
  while (through.Next()) {
    if (through.step() % 4 != 3) continue;
    ASSERT_TRUE(seek.SeekTo(through.step()));
    EXPECT_EQ(seek.step(), through.step());
    for (uint32_t id = 0; id < through.object_count(); ++id) {
      const Pose a = through.world_pose(id), b = seek.world_pose(id);
      EXPECT_EQ(a.p, b.p) << "step " << through.step() << " id " << id;
      EXPECT_EQ(a.q, b.q);
      EXPECT_EQ(through.reading(id), seek.reading(id));
    }
  }
  EXPECT_FALSE(seek.SeekTo(31));
  fs::remove_all(out);
}

TEST(RecordingTest, EveryNthStepKeepsTheSkippedStepsMetrics) {
  const fs::path out = TempDir("every");
  RecordSettings settings;
  settings.every = 5;
  auto l = LoadRecorded("worlds/diffusion.yaml", 10, out, settings);
  World& world = *l->loaded.world;
  world.Start();
  size_t run_samples = 0;
  for (int i = 0; i < 23; ++i) {
    world.Step();
    run_samples += world.TakeMetrics().size();
  }
  l->recorder->Finish(23, "ok", "");
  RecordingPlayer player(out);
  std::vector<int64_t> steps;
  size_t samples = 0;
  while (player.Next()) {
    steps.push_back(player.step());
    samples += player.samples().size();
  }
  EXPECT_EQ(steps, (std::vector<int64_t>{0, 5, 10, 15, 20}));
  // Step 10's and step 20's samples (every 10 steps) are in; none after step 20 was recorded.
  EXPECT_EQ(samples, run_samples);
  fs::remove_all(out);
}

TEST(RecordingTest, LedColoursAndThePaintLayerReadBack) {
  {
    const fs::path out = TempDir("leds");
    auto l = LoadRecorded("worlds/led_aggregation.yaml", 9, out);
    const World& world = RunRecorded(l.get(), 5);
    RecordingPlayer player(out);
    while (player.Next()) {
    }
    const Scene& scene = world.scene();
    ObjectType led{};
    ASSERT_TRUE(scene.FindType(kLedTypeName, &led));
    const std::vector<uint32_t> slots = RecordedSlots(scene);
    int leds = 0;
    std::set<uint32_t> colours;
    for (uint32_t id = 0; id < slots.size(); ++id) {
      if (scene.type_at(slots[id]) != led) continue;
      const LedRow& row =
          static_cast<const Rows<LedRow>&>(*scene.rows(led)).rows[scene.row_at(slots[id])];
      const uint32_t rgba = player.color_rgba(id);
      EXPECT_NEAR((rgba & 0xff) / 255.0, row.color.x, 0.5 / 255);
      EXPECT_NEAR(((rgba >> 8) & 0xff) / 255.0, row.color.y, 0.5 / 255);
      EXPECT_NEAR(((rgba >> 16) & 0xff) / 255.0, row.color.z, 0.5 / 255);
      EXPECT_EQ(rgba >> 24, row.on ? 1u : 0u);
      colours.insert(rgba);
      ++leds;
    }
    EXPECT_EQ(leds, 9);
    EXPECT_EQ(colours.size(), 3u);  // robot i gets colour i mod 3
    fs::remove_all(out);
  }
  {
    const fs::path out = TempDir("paint");
    auto l = LoadRecorded("worlds/trails.yaml", 6, out);
    const World& world = RunRecorded(l.get(), 30);
    RecordingPlayer player(out);
    while (player.Next()) {
    }
    const FloorLayer* paint = world.floor_layer();  // the paint layer
    ASSERT_NE(paint, nullptr);
    const FloorArea area = paint->floor_area();
    int64_t painted = 0;
    for (int row = 0; row < area.height; ++row)
      for (int column = 0; column < area.width; ++column)
        painted += paint->floor_marked(column, row);
    EXPECT_GT(painted, 100);
    const std::vector<uint8_t> rgb(paint->floor_rgb().begin(), paint->floor_rgb().end());
    EXPECT_EQ(player.paint_rgb(), rgb);
    // From the keyframe alone too (every painted cell is in it).
    RecordingPlayer seek(out);
    ASSERT_TRUE(seek.SeekTo(0));
    EXPECT_EQ(seek.paint_rgb().size(), rgb.size());
    fs::remove_all(out);
  }
}

TEST(RecordingTest, RobotsCopiedAndRemovedAtRunTimeGetANewScene) {
  const fs::path out = TempDir("respawn");
  // Failures per second: some robots fail soon, and copies replace them.
  auto l = LoadRecorded("worlds/respawn.yaml", 20, out, {}, {{"failure_rate", "0.5"}});
  World& world = *l->loaded.world;
  PoseTable poses;
  std::vector<size_t> robots;
  world.Start();
  for (int i = 0; i <= 30; ++i) {
    if (i > 0) world.Step();
    std::vector<Pose> row;
    for (const uint32_t slot : RecordedSlots(world.scene()))
      row.push_back(world.scene().world_pose_at(slot));
    poses.push_back(std::move(row));
  }
  l->recorder->Finish(30, "ok", "");
  RecordingPlayer player(out);
  int scenes = 0;
  for (const ChunkInfo& c : player.info().chunks)
    scenes += c.kind == static_cast<uint8_t>(ChunkKind::kScene);
  EXPECT_GT(scenes, 1);
  while (player.Next()) {
    const int64_t step = player.step();
    ASSERT_EQ(player.object_count(), poses[step].size()) << "step " << step;
    for (uint32_t id = 0; id < player.object_count(); ++id)
      ExpectNear(player.world_pose(id), poses[step][id],
                 "step " + std::to_string(step) + " id " + std::to_string(id));
  }
  EXPECT_EQ(player.step(), 30);
  fs::remove_all(out);
}

// A test type that declares a ray visual: its length and colour are its
// row's, which the test changes between steps.
struct BeamRow {
  double length = 2;
  double hit = -1;
  Vec3 color{0, 0, 1};
};
constinit const ObjectTypeDescriptor kBeamType{
    .name = "beam",
    .description = "a test marker",
    .make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
      return std::make_unique<Rows<BeamRow>>();
    },
    .visual =
        [](const Scene& scene, ObjectType type, uint32_t row, ObjectVisual* out) {
          const BeamRow& b = scene.rows<BeamRow>(type).rows[row];
          out->kind = VisualKind::kRay;
          out->size = {b.length, 0, 0};
          out->hit = b.hit;
          out->color = b.color;
        },
};

TEST(RecordingTest, ATypeIsRecordedAsItsVisualDeclaresIt) {
  const fs::path out = TempDir("declared");
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  registry.RegisterObjectType(std::shared_ptr<const ObjectTypeDescriptor>(
      std::shared_ptr<const ObjectTypeDescriptor>(), &kBeamType));
  WorldSettings ws;
  ws.physics = "kinematic";
  World world(ws, registry);
  world.set_log_sink([](std::string_view) {});
  Scene& scene = world.scene();
  ObjectType beam{};
  ASSERT_TRUE(scene.FindType("beam", &beam));
  // A robot whose root (a dummy: no visual) holds a beam; a dummy outside
  // any robot (not recorded).
  const ObjectId root = scene.AddDummy("bot", {}, {});
  scene.MakeModelInstance(root, "bot", "bot#0");
  const ObjectId b = scene.AddObject(beam, "beam", root, {}, nullptr);
  scene.AddDummy("lone", {}, {});
  RecordSettings settings;
  settings.out_dir = out;
  RunRecorder* recorder = AddRecorder(&world, settings);
  world.Start();
  world.Step();
  BeamRow& row = scene.row<BeamRow>(beam, b, "beam");
  row.hit = 0.5;  // a quarter of its length
  row.color = {1, 0, 0};
  world.Step();
  recorder->Finish(2, "ok", "");

  RecordingPlayer player(out);
  EXPECT_EQ(player.info().version_minor, kVersionMinor);
  ASSERT_TRUE(player.Next());
  const nlohmann::json j = nlohmann::json::parse(player.scene_json());
  const nlohmann::json& objects = j["templates"][0]["objects"];
  ASSERT_EQ(objects.size(), 2u);
  EXPECT_EQ(objects[0]["type"], "frame");
  EXPECT_EQ(objects[1]["type"], "beam");
  EXPECT_EQ(objects[1]["visual"], "ray");
  EXPECT_EQ(objects[1]["range"], 2);
  EXPECT_EQ(j["objects"].size(), 0u);
  std::vector<std::pair<uint16_t, uint32_t>> steps{{player.reading(1), player.color_rgba(1)}};
  while (player.Next()) steps.emplace_back(player.reading(1), player.color_rgba(1));
  const uint16_t quarter = static_cast<uint16_t>(std::lround(0.25 * 65534));
  EXPECT_EQ(steps,
            (std::vector<std::pair<uint16_t, uint32_t>>{
                {kNoDetection, 0x01ff0000}, {kNoDetection, 0x01ff0000}, {quarter, 0x010000ff}}));
  fs::remove_all(out);
}

// A chunk a reader would refuse (past kMaxChunkRawBytes decompressed,
// lowered here) is never written: the run fails naming the chunk, its step
// and the limit, and the file keeps every chunk before it and the end
// chunk, so that record-info and the viewer read it whole.
TEST(RecordingTest, AChunkPastTheReadersLimitEndsTheRecordingWhole) {
  const fs::path out = TempDir("too_large");
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  WorldSettings ws;
  ws.physics = "kinematic";
  World world(ws, registry);
  world.set_log_sink([](std::string_view) {});
  Scene& scene = world.scene();
  const ObjectId root = scene.AddDummy("bot", {}, {});
  scene.MakeModelInstance(root, "bot", "bot#0");
  ShapeData box;
  box.kind = ShapeKind::kBox;
  box.size = {0.1, 0.1, 0.1};
  scene.AddShape("body", root, {}, box);
  // At step 3, robot 0 copies itself 500 times: a scene of ~45 KB.
  scene.AttachScript(root, std::make_shared<const ScriptSource>(ScriptSource{"robot.lua", R"(
    local step = 0
    function sysCall_actuation()
      step = step + 1
      if step == 3 and sim.getRobotIndex() == 0 then
        for i = 1, 500 do sim.copyModel(sim.getObject(':')) end
      end
    end
  )"}));
  RecordSettings settings;
  settings.out_dir = out;
  settings.max_chunk_raw_bytes = 32 << 10;
  RunRecorder* recorder = AddRecorder(&world, settings);
  world.Start();
  // The error comes back from the recorder's thread at a later step, or at the end.
  std::string error;
  int steps = 0;
  while (steps < 20 && error.empty()) {
    try {
      world.Step();
      ++steps;
      if (steps == 20) recorder->WriteOutputs(out);
    } catch (const Error& e) {
      error = e.what();
    }
  }
  EXPECT_CONTAINS(error, (out / kRecordingFileName).string() + ": the scene of step 3 would hold ");
  EXPECT_CONTAINS(error, "bytes decompressed, past the 32768 bytes a recording chunk may hold");
  recorder->Finish(steps, "error", error);

  RecordingPlayer player(out);
  EXPECT_FALSE(player.info().truncated);
  ASSERT_FALSE(player.info().chunks.empty());
  EXPECT_EQ(player.info().chunks.back().kind, static_cast<uint8_t>(ChunkKind::kEnd));
  for (const ChunkInfo& c : player.info().chunks) EXPECT_LE(c.raw_size, uint32_t{32} << 10);
  EXPECT_EQ(player.info().step_records, 3) << "steps 0, 1 and 2";
  int64_t last = -1;
  while (player.Next()) last = player.step();
  EXPECT_EQ(last, 2);
  // The program reads it back whole, and says how the run ended.
  const testing::CommandResult info = testing::RunProgram("record-info " + out.string());
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_CONTAINS(info.output, "3 step records (steps 0..2)");
  EXPECT_CONTAINS(info.output, "the run ended (error: ");
  EXPECT_CONTAINS(info.output, "a recording chunk may hold");
  fs::remove_all(out);
}

// A world whose every keyframe would be past what a chunk may hold is
// refused as the recorder starts, saying how many robots would fit, not a
// step into the run by the recorder's thread.
TEST(RecordingTest, AWorldWhoseKeyframesCannotFitIsRefusedAtTheStart) {
  const fs::path out = TempDir("keyframe_too_large");
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  WorldSettings ws;
  ws.physics = "kinematic";
  World world(ws, registry);
  world.set_log_sink([](std::string_view) {});
  Scene& scene = world.scene();
  ShapeData box;
  box.kind = ShapeKind::kBox;
  box.size = {0.1, 0.1, 0.1};
  for (int i = 0; i < 100; ++i) {  // a dummy and a box each: 2 objects, 1 colour
    const ObjectId root = scene.AddDummy("bot", {}, Pose{{i * 1.0, 0, 0}, {}});
    scene.MakeModelInstance(root, "bot", "bot#" + std::to_string(i));
    scene.AddShape("body", root, {}, box);
  }
  RecordSettings settings;
  settings.out_dir = out;
  settings.max_chunk_raw_bytes = 4 << 10;  // 100 robots' keyframe: 200 x 28 + 100 x 8 bytes
  AddRecorder(&world, settings);
  std::string error;
  try {
    world.Start();
  } catch (const Error& e) {
    error = e.what();
  }
  EXPECT_CONTAINS(error,
                  "the recording: every keyframe of this world would hold at least 6.2 KiB "
                  "(200 recorded objects), past the 4.0 KiB a recording chunk may hold");
  EXPECT_CONTAINS(error, "record fewer robots (about 64 of these 100 would fit)");
  fs::remove_all(out);
}

}  // namespace
}  // namespace swarmsim::record
