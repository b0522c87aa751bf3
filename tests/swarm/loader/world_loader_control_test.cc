// World-file keys of distributed control: simulation.main_script /
// instruction_budget / on_script_error, per-copy parameters (instances:),
// parameter ranges, --set, and `swarmsim describe`.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "modules/kinematics/ik_groups.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/fakes.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

class ControlLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("swarmsim_control_loader_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Write("bot.yaml",
          "model: bot\n"
          "parameters:\n"
          "  speed: {default: 0.1, unit: m/s, range: [0, 0.5], description: forward speed}\n"
          "  label: {default: plain}\n"
          "objects: {name: body, type: dummy, script: bot.lua}\n");
    Write("bot.lua", "function sysCall_init() end\n");
    Write("main.lua", "function sysCall_step() sim.handleDynamics() end\n");
    registry_.RegisterDynamics({"", "kinematic", "1", "test"}, {},
                               [] { return std::make_unique<testing::NullDynamics>(); });
    proximity::Register(&registry_, {"", "proximity", "1", "test"},
                        [] { return std::make_unique<testing::NullProximity>(); });
    // The gear's `ik_groups:` is the kinematics module's model-file section.
    kinematics::Register(&registry_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
  }
  LoadedWorld Load(const std::string& world, LoadOptions options = {}) {
    Write("world.yaml", world);
    return LoadWorld(dir_ / "world.yaml", options, registry_);
  }
  std::string ErrorOf(const std::string& world, LoadOptions options = {}) {
    try {
      Load(world, options);
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  fs::path dir_;
  ModuleRegistry registry_;
};

const char kThree[] =
    "simulation: {physics: kinematic}\n"
    "models:\n"
    "  - model: bot.yaml\n"
    "    count: 3\n"
    "    distribute: {region: {min: [-5, -5], max: [5, 5]}}\n"
    "    parameters: {speed: 0.2}\n"
    "    instances:\n"
    "      - {index: 1, parameters: {speed: 0.4, label: special}}\n";

TEST_F(ControlLoaderTest, SimulationControlKeys) {
  LoadedWorld w = Load(
      "simulation: {physics: kinematic, main_script: main.lua, instruction_budget: 5000, "
      "on_script_error: disable_script}\n");
  EXPECT_EQ(w.world->settings().instruction_budget, 5000);
  EXPECT_EQ(w.world->settings().on_script_error, ScriptErrorPolicy::kDisableScript);
  ASSERT_TRUE(w.world->settings().main_script);
  EXPECT_CONTAINS(w.world->settings().main_script->code, "sim.handleDynamics()");
  LoadedWorld d = Load("simulation: {physics: kinematic}\n");
  EXPECT_EQ(d.world->settings().on_script_error, ScriptErrorPolicy::kStop);
  EXPECT_EQ(d.world->settings().robots_per_lua_state, 1);  // a state each unless asked
  EXPECT_EQ(Load("simulation: {physics: kinematic, robots_per_lua_state: 64}\n")
                .world->settings()
                .robots_per_lua_state,
            64);
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, robots_per_lua_state: 0}\n"),
                  "world.yaml:1:56:");
  EXPECT_FALSE(d.world->settings().main_script);
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, on_script_error: ignore}\n"),
                  "world.yaml:1:51:");
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, instruction_budget: -1}\n"),
                  "world.yaml:1:54:");
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, main_script: nothere.lua}\n"),
                  "nothere.lua");
  // Shorter than one step: an error, not a silent run of 0 steps.
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, time_step: 0.1, duration: 0.01}\n"),
                  "world.yaml:1:60: 'duration' 0.01 s is shorter than one time step (0.1 s)");
  // Half a step too, as --duration 0.05 is (it ran one step).
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic, time_step: 0.1, duration: 0.05}\n"),
                  "world.yaml:1:60: 'duration' 0.05 s is shorter than one time step (0.1 s)");
}

// A model whose objects use its parameters everywhere a value can.
const char kGear[] =
    "model: gear\n"
    "parameters:\n"
    "  r: {default: 0.3, unit: m, range: [0.05, 2]}\n"
    "  size: 0.1\n"
    "  lim: 0.5\n"
    "  mass: 1\n"
    "  damping: 0.01\n"
    "objects:\n"
    "  type: shape\n"
    "  shape: cylinder\n"
    "  radius: $size\n"
    "  height: \"= 2 * size\"\n"
    "  dynamic: true\n"
    "  mass: $mass\n"
    "  script: bot.lua\n"
    "  children:\n"
    "    - {name: s, type: proximity_sensor, position: [$size, 0, 0], range: $r}\n"
    "    - {name: ring, type: proximity_ring, count: 2, radius: $size, range: \"= r / 2\"}\n"
    "    - name: j\n"
    "      type: joint\n"
    "      mode: position\n"
    "      limits: [\"= -lim\", $lim]\n"
    "      children: [{name: tip, type: dummy, position: [0.1, 0, 0]}]\n"
    "    - {name: target, type: dummy, position: [0.05, 0.05, 0]}\n"
    "ik_groups:\n"
    "  - {name: reach, tips: [{tip: j/tip, target: target}], damping: $damping}\n";

TEST_F(ControlLoaderTest, PerCopyValuesReachEveryObjectValueThatUsesThem) {
  // instances: values changed what sim.getParam saw, but the objects were
  // built once for the whole entry: copy 0's sensor kept the entry's range.
  Write("gear.yaml", kGear);
  Write("world.yaml",
        "simulation: {physics: kinematic}\n"
        "models:\n"
        "  - model: gear.yaml\n"
        "    count: 3\n"
        "    distribute: {region: {min: [-5, -5], max: [5, 5]}, clearance: 0.1}\n"
        "    parameters: {mass: 1.5}\n"
        "    instances:\n"
        "      - {index: 0, parameters: {r: 1.8, size: 0.4, lim: 1, mass: 2, damping: 0.2}}\n"
        "      - {index: 2, parameters: {r: 0.3}}\n");  // the entry's values: shared
  ModuleRegistry builtin;
  RegisterBuiltinModules(&builtin);
  const LoadedWorld w = LoadWorld(dir_ / "world.yaml", {}, builtin);
  const Scene& scene = w.world->scene();
  ASSERT_EQ(scene.instances().size(), 3u);
  const auto* ik = kinematics::FindIkGroups(*w.world);
  ASSERT_NE(ik, nullptr);
  struct Expected {
    double r, size, lim, mass, damping;
  };
  const Expected expected[] = {
      {1.8, 0.4, 1, 2, 0.2}, {0.3, 0.1, 0.5, 1.5, 0.01}, {0.3, 0.1, 0.5, 1.5, 0.01}};
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE("copy " + std::to_string(k));
    const Expected& e = expected[k];
    const ObjectId root = scene.instance(k).root;
    EXPECT_EQ(std::get<double>(*w.world->FindParameter(k, "r")), e.r);
    EXPECT_EQ(proximity::Sensor(scene, scene.FindObject("./s", root)).range(), e.r);
    EXPECT_EQ(scene.local_pose(scene.FindObject("./s", root)).p.x, e.size);
    EXPECT_EQ(proximity::Sensor(scene, scene.FindObject("./ring[1]", root)).range(), e.r / 2);
    EXPECT_EQ(scene.shape(root).size.x, e.size);
    EXPECT_EQ(scene.shape(root).size.z, 2 * e.size);
    EXPECT_EQ(scene.shape(root).mass, e.mass);
    EXPECT_EQ(scene.joint(scene.FindObject("./j", root)).settings->min_position, -e.lim);
    EXPECT_EQ(scene.joint(scene.FindObject("./j", root)).settings->max_position, e.lim);
    EXPECT_EQ(ik->spec(ik->FindGroup("reach", k)).damping, e.damping);
    // Each copy stands on the ground by its own height.
    EXPECT_DOUBLE_EQ(scene.world_pose(root).p.z, e.size);
  }
  // Placement keeps the larger copy clear of the others by its own radius.
  for (int k = 1; k < 3; ++k) {
    const Vec3 d =
        scene.world_pose(scene.instance(0).root).p - scene.world_pose(scene.instance(k).root).p;
    EXPECT_GE(std::hypot(d.x, d.y), 0.4 + 0.1 + 0.1) << k;
  }
  // --set still sets every copy, and describe lists copy 0's values.
  LoadOptions set;
  set.overrides = {{"gear.r", "1.2"}};
  const LoadedWorld s = LoadWorld(dir_ / "world.yaml", set, builtin);
  for (int k = 0; k < 3; ++k) {
    const ObjectId root = s.world->scene().instance(k).root;
    EXPECT_EQ(proximity::Sensor(s.world->scene(), s.world->scene().FindObject("./s", root)).range(),
              1.2)
        << k;
  }
  ASSERT_EQ(w.models[0].instances.size(), 2u);
  EXPECT_EQ(w.models[0].instances[0].second, "damping=0.2, lim=1, mass=2, r=1.8, size=0.4");
  EXPECT_EQ(w.models[0].instances[1].second, "");
}

TEST_F(ControlLoaderTest, ACopysOwnValueThatBreaksAnObjectNamesTheCopy) {
  Write("gear.yaml", kGear);
  const std::string error = ErrorOf(
      "simulation: {physics: kinematic}\n"
      "models:\n"
      "  - model: gear.yaml\n"
      "    count: 2\n"
      "    distribute: {region: {min: [-5, -5], max: [5, 5]}}\n"
      "    instances: [{index: 1, parameters: {lim: -1}}]\n");
  EXPECT_CONTAINS(error,
                  "gear.yaml:22:15: 'limits' must be [min, max] with min <= max (with the "
                  "parameters of copy 1 given at ");
  EXPECT_CONTAINS(error, "world.yaml:6:17)");
}

TEST_F(ControlLoaderTest, AMisspelledRequiredKeyIsAnUnknownKeyWithASuggestion) {
  // 'model', 'type' and 'name' were reported missing before the keys were checked.
  EXPECT_CONTAINS(ErrorOf("models:\n  - modle: bot.yaml\n"),
                  "world.yaml:2:5: unknown key 'modle' in a models entry; did you mean 'model'?");
  EXPECT_CONTAINS(ErrorOf("models:\n  - {count: 1}\n"),
                  "world.yaml:2:5: 'model' is required in a models entry");
  const std::string world =
      "simulation: {physics: kinematic}\n"
      "models: [{model: bot.yaml, position: [0, 0]}]\n";
  Write("bot.yaml",
        "model: bot\n"
        "objects: {name: body, type: dummy, children: [{name: arm, tpye: dummy}]}\n");
  EXPECT_CONTAINS(ErrorOf(world),
                  "bot.yaml:2:59: unknown key 'tpye' in an object of model 'bot'; did you mean "
                  "'type'?");
  Write("bot.yaml",
        "model: bot\n"
        "objects: {name: body, type: dummy, children: [{nmae: arm, type: dummy}]}\n");
  EXPECT_CONTAINS(ErrorOf(world),
                  "bot.yaml:2:48: unknown key 'nmae' in an object of model 'bot'; did you mean "
                  "'name'?");
  Write("bot.yaml",
        "model: bot\n"
        "objects: {name: body, type: dummy, children: [{position: [1, 0, 0], type: dummy}]}\n");
  EXPECT_CONTAINS(ErrorOf(world), "bot.yaml:2:47: 'name' is required in an object of model 'bot'");
}

TEST_F(ControlLoaderTest, ARangeOrDefaultMistakeSaysWhatIsWrong) {
  Write("bot.yaml",
        "model: bot\nparameters:\n  speed: {default: 0.1, range: [0.3, 0]}\n"
        "objects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(
      ErrorOf(kThree),
      "bot.yaml:3:32: 'range' must be [min, max] with min <= max (got min 0.3 > max 0)");
  Write("bot.yaml",
        "model: bot\nparameters:\n  speed: {default: 0.1, range: [low, 1]}\n"
        "objects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(ErrorOf(kThree),
                  "bot.yaml:3:33: 'range' must be [min, max], two numbers: its min is not a "
                  "number (got \"low\")");
  Write("bot.yaml",
        "model: bot\nparameters:\n  speed: {default: fast, unit: m/s, range: [0, 1]}\n"
        "objects: {name: body, type: dummy}\n");
  EXPECT_CONTAINS(ErrorOf("simulation: {physics: kinematic}\n"
                          "models: [{model: bot.yaml, position: [0, 0]}]\n"),
                  "bot.yaml:3:20: the default of parameter 'speed' of model 'bot' must be a "
                  "number within [0, 1] m/s (got \"fast\", which is not a number)");
}

TEST_F(ControlLoaderTest, DescribeListsModelsParametersAndScripts) {
  Write("world.yaml", kThree);
  const std::string cmd = std::string(SWARMSIM_BINARY) + " describe " +
                          (dir_ / "world.yaml").string() + " --set bot.speed=0.25 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << out;
  EXPECT_CONTAINS(out, "model bot (");
  EXPECT_CONTAINS(out, "3 copies");
  EXPECT_CONTAINS(out, "script: ");
  EXPECT_CONTAINS(out, "bot.lua");
  EXPECT_CONTAINS(out, "bot.speed = 0.25 m/s  (default 0.1, range [0, 0.5])  forward speed");
  EXPECT_CONTAINS(out, "copy 1 of this entry: label=special");
}

// describe shows an entry's scale and, per script file, the objects it is on
// (paths from the model root) and which of them are explicit.
TEST_F(ControlLoaderTest, DescribeShowsScaleAndWhereEachScriptIsAttached) {
  Write("arm.yaml",
        "model: arm\n"
        "objects:\n"
        "  type: dummy\n"
        "  script: base.lua\n"
        "  children:\n"
        "    - {name: a, type: dummy, script: {file: link.lua, explicit: true},\n"
        "       children: [{name: b, type: dummy, script: link.lua}]}\n");
  Write("base.lua", "");
  Write("link.lua", "");
  Write("world.yaml",
        "models:\n  - {model: arm.yaml, count: 2, scale: 1.5, "
        "distribute: {region: {min: [-5, -5], max: [5, 5]}}}\n");
  const auto r = swarmsim::testing::RunProgram("describe " + (dir_ / "world.yaml").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "arm.yaml): 2 copies, scale 1.5\n");
  EXPECT_CONTAINS(r.output, "/base.lua on :\n");
  EXPECT_CONTAINS(r.output, "/link.lua on :/a (explicit), :/a/b\n");
}

// --- Script errors and warnings, as the program reports them ---------------------------------

// `swarmsim run` of world.yaml in the test folder.
swarmsim::testing::CommandResult RunWorld(const fs::path& dir, const std::string& args) {
  return swarmsim::testing::RunProgram("run " + (dir / "world.yaml").string() + " " + args);
}

const char kTwoBots[] =
    "models:\n"
    "  - model: bot.yaml\n"
    "    count: 2\n"
    "    distribute: {region: {min: [-5, -5], max: [5, 5]}}\n";

TEST_F(ControlLoaderTest, ManyArgumentsToHandleChildScriptsDoNotCrashTheRun) {
  Write("main.lua",
        "function sysCall_step() local t={} for i=1,45 do t[i]=i end sim.handleSensing() "
        "sim.handleChildScripts('actuation', table.unpack(t)) sim.handleActuation() "
        "sim.handleDynamics() end\n");
  Write("bot.lua", "function sysCall_actuation(...) print(select('#',...)) end\n");
  Write("world.yaml",
        std::string("simulation: {physics: kinematic, main_script: main.lua}\n") + kTwoBots);
  const auto r = RunWorld(dir_, "--steps 2 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "[bot#0] 45\n[bot#1] 45\n[bot#0] 45\n[bot#1] 45\n");
}

TEST_F(ControlLoaderTest, DisabledCleanupAndMainChunkErrorsEndTheRunOkAndAreListed) {
  Write("bot.lua",
        "if sim.getRobotIndex() == 1 then error('boom') end\n"
        "function sysCall_cleanup()\n  error('bye')\nend\n");
  Write("world.yaml",
        std::string("simulation: {physics: kinematic, on_script_error: disable_script}\n") +
            kTwoBots);
  const fs::path out = dir_ / "out";
  const auto r = RunWorld(dir_, "--steps 2 --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream summary_file(out / "summary.json");
  ASSERT_TRUE(summary_file.good());
  const auto summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary["status"], "ok") << summary.dump();
  ASSERT_EQ(summary["disabled_scripts"].size(), 2u) << summary.dump();
  const std::string script = (dir_ / "bot.lua").string();
  EXPECT_EQ(summary["disabled_scripts"][0],
            "bot#1: " + script + ":1: boom [in the main chunk of /bot#1]");
  EXPECT_EQ(summary["disabled_scripts"][1],
            "bot#0: " + script + ":3: bye [in sysCall_cleanup of /bot#0]");
  EXPECT_CONTAINS(r.output, "disabled scripts 2");
  // Under stop, the cleanup error still ends the run.
  Write("bot.lua", "function sysCall_cleanup()\n  error('bye')\nend\n");
  Write("world.yaml", std::string("simulation: {physics: kinematic}\n") + kTwoBots);
  const auto stopped = RunWorld(dir_, "--steps 1 --quiet");
  EXPECT_EQ(stopped.exit_code, 1) << stopped.output;
  EXPECT_CONTAINS(stopped.output,
                  "error: bot#0: " + script + ":2: bye [in sysCall_cleanup of /bot#0]");
}

TEST_F(ControlLoaderTest, ACallbackTypoIsWarnedOnceForAThousandRobots) {
  Write("bot.lua", "function sysCall_actuate() end\n");
  Write("world.yaml",
        "simulation: {physics: kinematic}\n"
        "models:\n"
        "  - model: bot.yaml\n"
        "    count: 1000\n"
        "    distribute: {region: {min: [-50, -50], max: [50, 50]}}\n");
  const auto r = RunWorld(dir_, "--steps 1 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string warning =
      "warning: " + (dir_ / "bot.lua").string() +
      ":1: defines sysCall_actuate, which swarmsim never calls (did you mean "
      "sysCall_actuation?)\n";
  const size_t first = r.output.find(warning);
  EXPECT_NE(first, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("sysCall_actuate,", first + warning.size()), std::string::npos)
      << r.output;
}

TEST_F(ControlLoaderTest, ACopysOwnSensorRangeIsWhatItsSensorReads) {
  // Two robots 1 m apart, facing each other's side; copy 0's own range
  // (1.8 m) reaches the other, the entry's default (0.3 m) does not.
  Write("m.yaml",
        "model: p\n"
        "parameters: {r: {default: 0.3, unit: m, range: [0.05, 2]}}\n"
        "objects: {type: shape, shape: cylinder, radius: 0.05, height: 0.1, script: p.lua,\n"
        "  children: [{name: s, type: proximity_sensor, position: [0.05,0,0], "
        "orientation_deg: [0,90,0], range: $r}]}\n");
  Write("p.lua",
        "function sysCall_sensing() local d, x = sim.readProximitySensor(sim.getObject('./s')) "
        "print(sim.getParam('r'), d, x ~= nil) end\n");
  Write("world.yaml",
        "simulation: {physics: kinematic, steps: 1}\n"
        "models:\n"
        "  - {model: m.yaml, count: 2, distribute: {region: {min: [-0.06,-1], max: [0.06,1]}, "
        "heading_deg: 90, clearance: 0.5},\n"
        "     instances: [{index: 0, parameters: {r: 1.8}}]}\n");
  const auto r = RunWorld(dir_, "--quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_CONTAINS(r.output, "[p#0] 1.8\t1\ttrue\n");
  EXPECT_CONTAINS(r.output, "[p#1] 0.3\t0\tfalse\n");
}

}  // namespace
}  // namespace swarmsim
