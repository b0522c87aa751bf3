// Loading worlds and models as a user writes them: what ends up in the
// scene, how overrides and seeds act, and what each mistake says.
#include "swarm/loader/world_loader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <string>

#include "framework/error.h"
#include "framework/random.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/metrics/swarm_metrics.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;

const std::string kDiffusion = std::string(SWARMSIM_SOURCE_DIR) + "/worlds/diffusion.yaml";

// "box2d" and "null" dynamics that never run here (no test calls Start()).
ModuleRegistry TestRegistry() {
  ModuleRegistry r;
  for (const char* name : {"box2d", "null"})
    r.RegisterDynamics({"", name, "1", "test double"}, {},
                       [] { return std::make_unique<testing::NullDynamics>(); });
  proximity::Register(&r, {"", "proximity", "1", "test double"},
                      [] { return std::make_unique<testing::NullProximity>(); });
  for (ModuleDescriptor& metric : metrics::SwarmMetricModules()) r.RegisterModule(metric);
  r.RegisterWorldSection(metrics::MetricsSection());
  return r;
}

LoadedWorld Load(const fs::path& file, LoadOptions options = {}) {
  static const ModuleRegistry registry = TestRegistry();
  return LoadWorld(file, options, registry);
}

LoadedWorld LoadDiffusion(std::vector<std::pair<std::string, std::string>> overrides,
                          std::optional<uint64_t> seed = std::nullopt) {
  LoadOptions options;
  options.overrides = std::move(overrides);
  options.seed = seed;
  return Load(kDiffusion, options);
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("NOT A swarmsim::Error: ") + e.what();
  }
  return "NO ERROR";
}

std::vector<Vec3> RootPositions(const World& world) {
  std::vector<Vec3> out;
  for (const ModelInstance& inst : world.scene().instances())
    out.push_back(world.scene().world_pose(inst.root).p);
  return out;
}

double Get(const World& world, int instance, const std::string& name) {
  const ParamValue* v = world.FindParameter(instance, name);
  return v ? std::get<double>(*v) : NAN;
}

void ExpectNear(const Vec3& a, const Vec3& b, double tol = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// --- The example world ------------------------------------------------------------------

TEST(WorldLoaderTest, DiffusionBuildsThreeHundredFootbots) {
  LoadedWorld loaded = LoadDiffusion({{"robots", "300"}});
  const World& world = *loaded.world;
  const Scene& scene = world.scene();
  ASSERT_EQ(world.robot_count(), 300);
  EXPECT_FALSE(world.started());
  EXPECT_EQ(world.settings().physics, "box2d");
  EXPECT_DOUBLE_EQ(world.settings().time_step, 0.1);
  EXPECT_EQ(world.settings().physics_substeps, 10);
  EXPECT_EQ(world.settings().seed, 1u);
  ASSERT_TRUE(loaded.steps.has_value());
  EXPECT_EQ(*loaded.steps, 600);  // 60 s at 10 Hz
  // Its `metrics:` entry ({name: ..., every: 10}: tests/swarm/loader/world_sections_test.cc).
  EXPECT_EQ(loaded.metric_names, std::vector<std::string>{"mean_nearest_neighbor_distance"});
  EXPECT_EQ(std::get<double>(world.parameters().at("robots")), 300);

  const ScriptSource* shared_script = nullptr;
  for (int i = 0; i < 300; ++i) {
    const ModelInstance& inst = scene.instance(i);
    EXPECT_EQ(inst.name, "footbot#" + std::to_string(i));
    EXPECT_EQ(inst.model_name, "footbot");
    EXPECT_EQ(scene.name(inst.root), inst.name);
    int sensors = 0, joints = 0, shapes = 0;
    for (uint32_t slot : inst.objects) {
      sensors += proximity::IsSensorAt(scene, slot);
      joints += scene.type_at(slot) == ObjectType::kJoint;
      shapes += scene.type_at(slot) == ObjectType::kShape;
    }
    EXPECT_EQ(sensors, 24);
    EXPECT_EQ(joints, 2);
    EXPECT_EQ(shapes, 3);  // body and two wheels
    // The body carries the controller; all copies share one source.
    const ScriptAttachment* script = scene.script(inst.root);
    ASSERT_NE(script, nullptr);
    EXPECT_TRUE(script->source->path.ends_with("scripts/diffusion.lua")) << script->source->path;
    EXPECT_FALSE(script->source->code.empty());
    if (!shared_script) shared_script = script->source.get();
    EXPECT_EQ(script->source.get(), shared_script);
    const ShapeData& body = scene.shape(inst.root);
    EXPECT_TRUE(body.dynamic);
    EXPECT_EQ(body.kind, ShapeKind::kCylinder);
    EXPECT_DOUBLE_EQ(body.size.x, 0.085);
    EXPECT_DOUBLE_EQ(body.mass, 1.6);
    // Standing on the ground.
    EXPECT_NEAR(scene.world_pose(inst.root).p.z, 0.073, 1e-12);
    // Model parameters: one set shared by every copy.
    EXPECT_EQ(Get(world, i, "wheel_speed"), 0.05);
  }
  // The walls: inner side sqrt(robots / density) = sqrt(300).
  const double side = std::sqrt(300.0);
  const ObjectId north = scene.FindObject("/wall_north");
  const ObjectId east = scene.FindObject("/wall_east");
  ASSERT_FALSE(north.IsNull());
  ASSERT_FALSE(east.IsNull());
  EXPECT_EQ(scene.instance_of(north), -1);
  EXPECT_FALSE(scene.shape(north).dynamic);
  EXPECT_NEAR(scene.shape(north).size.x, side + 0.2, 1e-9);
  EXPECT_NEAR(scene.world_pose(north).p.y, side / 2 + 0.05, 1e-9);
  EXPECT_NEAR(scene.world_pose(east).p.x, side / 2 + 0.05, 1e-9);
}

TEST(WorldLoaderTest, FootbotGeometryFollowsTheConventions) {
  LoadedWorld loaded = LoadDiffusion({{"robots", "3"}});
  const Scene& scene = loaded.world->scene();
  const ObjectId root = scene.instance(1).root;
  const Pose X_WB = scene.world_pose(root);
  const ObjectId left = scene.FindObject("./leftMotor", root);
  const ObjectId right = scene.FindObject("./rightMotor", root);
  ASSERT_FALSE(left.IsNull());
  ASSERT_FALSE(right.IsNull());
  // Joints 0.029 m above the ground, 0.07 m left and right of the centre.
  const Pose X_BL = X_WB.Inverse() * scene.world_pose(left);
  ExpectNear(X_BL.p, {0, 0.07, -0.044});
  EXPECT_NEAR(scene.world_pose(left).p.z, 0.029, 1e-12);
  ExpectNear((X_WB.Inverse() * scene.world_pose(right)).p, {0, -0.07, -0.044});
  // Both axles (joint z) along the body's +y: positive velocity rolls forward.
  ExpectNear(X_BL.q.Rotate({0, 0, 1}), {0, 1, 0});
  ExpectNear((X_WB.Inverse() * scene.world_pose(right)).q.Rotate({0, 0, 1}), {0, 1, 0});
  EXPECT_EQ(scene.joint(left).mode(), JointMode::kVelocity);
  EXPECT_EQ(scene.joint(left).type(), JointType::kRevolute);
  const ObjectId wheel = scene.FindObject("./leftMotor/leftWheel", root);
  ASSERT_FALSE(wheel.IsNull());
  EXPECT_DOUBLE_EQ(scene.shape(wheel).size.x, 0.029);
  EXPECT_FALSE(scene.shape(wheel).dynamic);
  // Sensor i at 15 i degrees counter-clockwise from the front, ray outwards.
  for (int i : {0, 6, 13}) {
    const ObjectId s = scene.FindObject("./prox[" + std::to_string(i) + "]", root);
    ASSERT_FALSE(s.IsNull()) << i;
    const Pose X_BS = X_WB.Inverse() * scene.world_pose(s);
    const double theta = 2 * M_PI * i / 24;
    ExpectNear(X_BS.p, {0.085 * std::cos(theta), 0.085 * std::sin(theta), -0.013});
    ExpectNear(X_BS.q.Rotate({0, 0, 1}), {std::cos(theta), std::sin(theta), 0});
    EXPECT_DOUBLE_EQ(proximity::Sensor(scene, s).range(), 0.1);
  }
}

// --- Overrides and seeds ---------------------------------------------------------------------

TEST(WorldLoaderTest, OverridesChangeWorldAndModelParameters) {
  LoadedWorld loaded = LoadDiffusion({{"density", "4"}, {"footbot.wheel_speed", "0.1"}});
  const World& world = *loaded.world;
  EXPECT_EQ(world.robot_count(), 100);
  // Arena side sqrt(100 / 4) = 5.
  EXPECT_NEAR(world.scene().shape(world.scene().FindObject("/wall_east")).size.y, 5, 1e-12);
  EXPECT_EQ(Get(world, 0, "wheel_speed"), 0.1);
  EXPECT_EQ(Get(world, 99, "wheel_speed"), 0.1);
  EXPECT_EQ(Get(world, 0, "wheel_radius"), 0.029);  // untouched default
  // Later overrides win.
  LoadedWorld twice = LoadDiffusion({{"robots", "10"}, {"robots", "20"}});
  EXPECT_EQ(twice.world->robot_count(), 20);
}

TEST(WorldLoaderTest, BadOverridesAreErrorsWithSuggestions) {
  EXPECT_NE(ErrorOf([] {
              LoadDiffusion({{"robts", "5"}});
            }).find("did you mean 'robots'?"),
            std::string::npos);
  const std::string model = ErrorOf([] { LoadDiffusion({{"footbot.wheel_sped", "1"}}); });
  EXPECT_NE(model.find("did you mean 'footbot.wheel_speed'?"), std::string::npos) << model;
  const std::string no_model = ErrorOf([] { LoadDiffusion({{"fotbot.delta", "1"}}); });
  EXPECT_NE(no_model.find("no model 'fotbot'"), std::string::npos) << no_model;
  EXPECT_NE(no_model.find("footbot.delta"), std::string::npos) << no_model;
  // A simulation: key is no parameter: how to make it one (a suggestion of
  // 'robots' for robots_per_lua_state, or "no model 'simulation'", said nothing).
  const std::string sim = ErrorOf([] { LoadDiffusion({{"simulation.physics", "planar"}}); });
  EXPECT_NE(sim.find("no model 'simulation'"), std::string::npos) << sim;
  EXPECT_NE(sim.find("simulation: settings are not parameters --set can change"), std::string::npos)
      << sim;
  EXPECT_NE(sim.find("`physics: $physics`), then --set physics=..."), std::string::npos) << sim;
  const std::string key = ErrorOf([] { LoadDiffusion({{"robots_per_lua_state", "1"}}); });
  EXPECT_NE(key.find("`robots_per_lua_state: $robots_per_lua_state`"), std::string::npos) << key;
  EXPECT_EQ(key.find("did you mean"), std::string::npos) << key;
  const std::string type = ErrorOf([] { LoadDiffusion({{"robots", "many"}}); });
  EXPECT_NE(type.find("--set robots=many"), std::string::npos) << type;
  EXPECT_NE(type.find("is a finite number"), std::string::npos) << type;
  EXPECT_NE(type.find("diffusion.yaml:14:11"), std::string::npos) << type;
  // "nan" reads as a number to strtod, never as a parameter's.
  const std::string nan = ErrorOf([] { LoadDiffusion({{"robots", "nan"}}); });
  EXPECT_NE(nan.find("--set robots=nan: parameter 'robots' is a finite number"), std::string::npos)
      << nan;
  const std::string negative = ErrorOf([] { LoadDiffusion({{"robots", "-5"}}); });
  EXPECT_NE(negative.find("'size'"), std::string::npos) << negative;
}

TEST(WorldLoaderTest, SeedDecidesPlacement) {
  const auto a = RootPositions(*LoadDiffusion({{"robots", "50"}}, 7).world);
  const auto b = RootPositions(*LoadDiffusion({{"robots", "50"}}, 7).world);
  const auto c = RootPositions(*LoadDiffusion({{"robots", "50"}}, 8).world);
  ASSERT_EQ(a.size(), 50u);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // The file's seed applies without --seed, and --seed replaces it.
  EXPECT_EQ(LoadDiffusion({{"robots", "5"}}).world->settings().seed, 1u);
  EXPECT_EQ(LoadDiffusion({{"robots", "5"}}, 8).world->settings().seed, 8u);
}

// --- Mistakes --------------------------------------------------------------------------------

// A scratch folder with a small valid model and script, for worlds written inline.
class MalformedWorldTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("swarmsim_loader_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Write("bot.lua", "function sysCall_init() end\n");
    Write("bot.yaml", kBot);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  std::string LoadText(const std::string& text, LoadOptions options = {}) {
    const fs::path file = Write("world.yaml", text);
    return ErrorOf([&] { Load(file, options); });
  }

  static constexpr const char* kBot =
      "model: bot\n"
      "parameters:\n"
      "  speed: {default: 0.05, unit: m/s, description: forward speed}\n"
      "objects:\n"
      "  name: body\n"
      "  type: shape\n"
      "  shape: cylinder\n"
      "  radius: 0.05\n"
      "  height: 0.05\n"
      "  dynamic: true\n"
      "  script: bot.lua\n";
  static constexpr const char* kModels =
      "models:\n"
      "  - model: bot.yaml\n"
      "    count: 3\n"
      "    distribute: {region: arena}\n";

  fs::path dir_;
};

TEST_F(MalformedWorldTest, ValidBaseLoads) {
  const fs::path file = Write("world.yaml", std::string("arena: {size: 2}\n") + kModels);
  LoadedWorld loaded = Load(file);
  EXPECT_EQ(loaded.world->robot_count(), 3);
  EXPECT_FALSE(loaded.steps.has_value());
}

// A world parameter may name the model file (a sweep over robots): its
// default, then --set's; a parameter naming no file is the usual error.
TEST_F(MalformedWorldTest, AParameterMayNameTheModelFile) {
  Write("other.yaml", std::string(kBot).replace(7, 3, "other"));  // "model: other"
  const fs::path world = Write("world.yaml",
                               "parameters: {robot_file: bot.yaml}\n"
                               "models:\n  - {model: $robot_file, position: [0, 0]}\n");
  EXPECT_EQ(Load(world).world->scene().instance(0).model_name, "bot");
  LoadOptions options;
  options.overrides = {{"robot_file", "other.yaml"}};
  EXPECT_EQ(Load(world, options).world->scene().instance(0).model_name, "other");
  options.overrides = {{"robot_file", "missing.yaml"}};
  EXPECT_NE(ErrorOf([&] { Load(world, options); }).find("missing.yaml"), std::string::npos);
}

TEST_F(MalformedWorldTest, PhysicsPartitionsIsAutoOrACount) {
  EXPECT_EQ(Load(Write("world.yaml", std::string("arena: {size: 2}\n") + kModels))
                .world->settings()
                .physics_partitions,
            1);
  EXPECT_EQ(Load(Write("world.yaml", std::string("arena: {size: 2}\nsimulation: "
                                                 "{physics_partitions: auto}\n") +
                                         kModels))
                .world->settings()
                .physics_partitions,
            0);
  EXPECT_EQ(Load(Write("world.yaml", std::string("arena: {size: 2}\nparameters: {p: 3}\n"
                                                 "simulation: {physics_partitions: $p}\n") +
                                         kModels))
                .world->settings()
                .physics_partitions,
            3);
  // From a parameter whose value is auto (a sweep over 1 and auto), and that
  // parameter set to a count on the command line (it holds "4" as text).
  const fs::path from_parameter =
      Write("world.yaml", std::string("arena: {size: 2}\nparameters: {p: auto}\n"
                                      "simulation: {physics_partitions: $p}\n") +
                              kModels);
  EXPECT_EQ(Load(from_parameter).world->settings().physics_partitions, 0);
  LoadOptions options;
  options.overrides = {{"p", "4"}};
  EXPECT_EQ(Load(from_parameter, options).world->settings().physics_partitions, 4);
  options.overrides = {{"p", "lots"}};
  const std::string error = ErrorOf([&] { Load(from_parameter, options); });
  EXPECT_NE(error.find("world.yaml:3:34: 'physics_partitions' must be auto or a whole number "
                       "from 1 to 1024 (got \"lots\" from \"$p\")"),
            std::string::npos)
      << error;
}

struct BadCase {
  const char* label;
  std::string world;                   // world.yaml
  std::vector<std::string> fragments;  // all must appear in the message
  std::string model = "";              // bot.yaml replacement, if any
};

TEST_F(MalformedWorldTest, EachMistakeHasAClearMessage) {
  const std::string models = kModels;
  const std::vector<BadCase> cases = {
      {"unknown top key",
       "arena: {size: 2}\nmodles: []\n",
       {"world.yaml:2:1:", "unknown key 'modles'", "did you mean 'models'?"}},
      {"unknown arena key",
       "arena:\n  size: 2\n  wall_thicknes: 0.1\n",
       {"world.yaml:3:3:", "did you mean 'wall_thickness'?"}},
      {"not a number",
       "arena: {size: abc}\n",
       {"world.yaml:1:15:", "'size'", "positive number", "(got \"abc\")"}},
      {"negative size", "arena: {size: -3}\n", {"world.yaml:1:15:", "positive number", "-3"}},
      {"nan size", "arena: {size: .nan}\n", {"world.yaml:1:15:", "positive number"}},
      {"partitions not auto or a number",
       "arena: {size: 2}\nsimulation: {physics_partitions: automatic}\n",
       {"world.yaml:2:34:", "'physics_partitions' must be auto or a whole number from 1 to 1024",
        "(got \"automatic\")"}},
      {"zero partitions",
       "arena: {size: 2}\nsimulation: {physics_partitions: 0}\n",
       {"world.yaml:2:34:", "'physics_partitions' must be auto or a whole number from 1 to 1024",
        "(got \"0\")"}},
      {"inf size", "arena: {size: inf}\n", {"positive number"}},
      {"huge size",
       "arena: {size: 1e300}\n",
       {"world.yaml:1:15:", "'size' must be at most 1000000 (got \"1e300\")"}},
      {"expression gives a negative size",
       "parameters: {robots: 4}\narena: {size: '= -sqrt(robots)'}\n",
       {"world.yaml:2:15:", "positive number", "-2 from"}},
      {"unknown name in expression",
       "parameters: {robots: 4, density: 1}\narena: {size: '= sqrt(robots / densty)'}\n",
       {"world.yaml:2:15:", "sqrt(robots / densty)", "unknown name 'densty'",
        "did you mean 'density'?"}},
      {"a parameter of text in arithmetic",
       "parameters: {robots: lots, density: 1}\narena: {size: '= sqrt(robots / density)'}\n",
       {"world.yaml:2:15:", "in expression 'sqrt(robots / density)' for 'size'",
        "(global 'robots'); with robots = \"lots\", density = 1"}},
      {"expression syntax",
       "arena: {size: '= 2 +'}\n",
       {"world.yaml:1:15:", "in expression '2 +'"}},
      {"runaway expression",
       "arena: {size: '= (function() while true do end end)()'}\n",
       {"world.yaml:1:15:", "the expression ran more than 1000000 Lua instructions"}},
      {"expression holding too much memory",
       "arena: {size: '= (function() local s = \"x\" for i = 1, 40 do s = s .. s end "
       "return #s end)()'}\n",
       {"world.yaml:1:15:", "the expression", "past 64 MiB of Lua memory"}},
      {"no libraries in expressions",
       "arena: {size: '= os.exit(1)'}\n",
       {"world.yaml:1:15:", "unknown name 'os'"}},
      {"unknown parameter reference",
       "parameters: {robots: 4}\nmodels:\n  - model: bot.yaml\n    count: $robot\n"
       "    distribute: {region: arena}\narena: {size: 2}\n",
       {"world.yaml:4:12:", "unknown parameter '$robot'", "did you mean 'robots'?"}},
      {"unknown physics",
       "simulation: {physics: bax2d}\n",
       {"world.yaml:1:23:", "unknown physics backend 'bax2d'", "did you mean 'box2d'?",
        "available: box2d, null"}},
      {"steps and duration",
       "simulation: {steps: 10, duration: 5}\n",
       {"either 'duration'", "or 'steps'"}},
      {"fractional count",
       "arena: {size: 2}\nmodels:\n  - {model: bot.yaml, count: 2.5, distribute: {}}\n",
       {"world.yaml:3:30:", "'count' must be a whole number from 0 to 1,000,000 (got \"2.5\")"}},
      {"a parameter's name without its $",
       "parameters: {robots: 4}\narena: {size: 2}\nmodels:\n"
       "  - {model: bot.yaml, count: robots, distribute: {}}\n",
       {"world.yaml:4:30:", "'count' must be a whole number", "(got \"robots\")",
        "did you mean '$robots', the parameter?"}},
      {"count from an expression past any bound",
       "parameters: {n: 1e300}\narena: {size: 2}\nmodels:\n"
       "  - {model: bot.yaml, count: '= n * 2', distribute: {}}\n",
       {"world.yaml:4:30:", "'count' must be a whole number from 0 to 1,000,000 (got 2e+300"}},
      {"missing model file",
       "arena: {size: 2}\nmodels:\n  - {model: nobot.yaml, count: 1, distribute: {}}\n",
       {"world.yaml:3:13:", "model file 'nobot.yaml' not found (looked for /",
        "/nobot.yaml; a path in a file is relative to that file's folder)"}},
      {"no placement",
       "arena: {size: 2}\nmodels:\n  - {model: bot.yaml}\n",
       {"world.yaml:3:5:", "'distribute'"}},
      {"region without arena",
       "models:\n  - {model: bot.yaml, count: 2, distribute: {}}\n",
       {"needs an 'arena'"}},
      {"missing script file",
       "arena: {size: 2}\n" + models,
       {"bot.yaml:5:11:", "script file 'nobot.lua' not found"},
       "model: bot\nobjects:\n  type: shape\n  shape: box\n  script: nobot.lua\n  size: [0.1, 0.1, "
       "0.1]\n"},
      {"typo in model",
       "arena: {size: 2}\n" + models,
       {"bot.yaml:6:3:", "unknown key 'raduis' in the root object of model 'bot'",
        "did you mean 'radius'?"},
       "model: bot\nobjects:\n  type: shape\n  shape: cylinder\n  radius: 0.05\n  raduis: 0.05\n  "
       "height: 0.1\n"},
      {"wrong shape key",
       "arena: {size: 2}\n" + models,
       {"bot.yaml:5:3:", "'size' does not apply to a cylinder"},
       "model: bot\nobjects:\n  type: shape\n  shape: cylinder\n  size: [1, 1, 1]\n"},
      {"bad object type",
       "arena: {size: 2}\n" + models,
       {"bot.yaml:3:9:", "'type' must be one of", "did you mean 'joint'?"},
       "model: bot\nobjects:\n  type: jiont\n"},
      {"bad position",
       "arena: {size: 2}\n" + models,
       {"bot.yaml:5:16:", "'position' must be a list of 3 numbers"},
       "model: bot\nobjects:\n  type: dummy\n  children:\n  - {position: [1, 2], name: x, type: "
       "dummy}\n"},
      {"bad model parameter in world",
       "arena: {size: 2}\n" + models + "    parameters: {sped: 1}\n",
       {"world.yaml:6:18:", "model 'bot' has no parameter 'sped'", "did you mean 'speed'?"}},
      {"model parameter type",
       "arena: {size: 2}\n" + models + "    parameters: {speed: fast}\n",
       {"world.yaml:6:25:", "is a finite number", "\"fast\"", "bot.yaml:3:20"}},
      {"duplicate key",
       "arena: {size: 2, size: 3}\n",
       {"world.yaml:1:18:", "duplicate key 'size'"}},
      {"too full",
       "arena: {size: 0.5}\nmodels:\n  - {model: bot.yaml, count: 1000, distribute: {}}\n",
       {"world.yaml:3:30:", "cannot place 1,000 bot copies in the arena without overlap (placed ",
        "enlarge the arena or reduce count"}},
      {"unknown metric",
       "metrics: [{name: mean_nearest_neighbour_distance}]\n",
       {"world.yaml:1:18:", "unknown metric", "did you mean 'mean_nearest_neighbor_distance'?"}},
      {"yaml syntax", "arena: {size: [1, 2}\n", {"world.yaml:1:", "YAML syntax error"}},
      {"tab indentation", "arena:\n\tsize: 2\n", {"world.yaml:", "YAML"}},
  };
  for (const BadCase& c : cases) {
    Write("bot.yaml", c.model.empty() ? kBot : c.model);
    const std::string message = LoadText(c.world);
    for (const std::string& fragment : c.fragments)
      EXPECT_NE(message.find(fragment), std::string::npos)
          << c.label << ": expected '" << fragment << "' in: " << message;
  }
}

// A script that does not parse is an error of the world as it loads, at the
// script's line (it was every robot's error at start, exit 1).
TEST_F(MalformedWorldTest, AScriptThatDoesNotParseIsNamedAsItLoads) {
  Write("broken.lua", "function sysCall_init()\n  x = = 1\nend\n");
  Write("bot.yaml",
        "model: bot\nobjects:\n  type: shape\n  shape: box\n  script: broken.lua\n  size: [0.1, "
        "0.1, 0.1]\n");
  const std::string message =
      LoadText("arena: {size: 2}\nmodels:\n  - {model: bot.yaml, count: 2, distribute: {}}\n");
  EXPECT_NE(message.find("bot.yaml:5:11: script "), std::string::npos) << message;
  EXPECT_NE(message.find("/broken.lua:2: unexpected symbol near '='"), std::string::npos)
      << "its path whole: " << message;
  // The world's main script too.
  const std::string main_script = LoadText("simulation: {main_script: broken.lua}\n");
  EXPECT_NE(main_script.find("world.yaml:1:"), std::string::npos) << main_script;
  EXPECT_NE(main_script.find("broken.lua:2: unexpected symbol"), std::string::npos) << main_script;
  // Compiled Lua: "script attempt to load a binary chunk (mode is 't')".
  Write("compiled.lua", std::string("\x1bLua\x54\x00junk", 10));
  const std::string compiled = LoadText("simulation: {main_script: compiled.lua}\n");
  EXPECT_NE(compiled.find("compiled.lua' is compiled Lua (a binary chunk, as luac writes it)"),
            std::string::npos)
      << compiled;
}

// A UTF-8 byte-order mark (Windows editors) and a `#!` first line are
// skipped as the `lua` program skips them: they were "unexpected symbol
// near '<\239>'". The lines keep their numbers.
TEST_F(MalformedWorldTest, AByteOrderMarkAndAShebangLineAreSkippedAsLuaSkipsThem) {
  Write("marked.lua", "\xEF\xBB\xBF#!/usr/bin/env lua\nfunction sysCall_init() end\n");
  EXPECT_EQ(LoadText("simulation: {main_script: marked.lua}\n"), "NO ERROR");
  Write("shebang.lua", "#!/usr/bin/lua\n\nx = = 1\n");
  const std::string message = LoadText("simulation: {main_script: shebang.lua}\n");
  EXPECT_NE(message.find("shebang.lua:3: unexpected symbol near '='"), std::string::npos)
      << "its own line number: " << message;
}

TEST_F(MalformedWorldTest, TabIndentationSaysYamlDoesNotAllowTabs) {
  const std::string hint = "(YAML does not allow tabs for indentation)";
  // A tab alone, a tab after spaces, a tab before a list entry.
  for (const std::string& world :
       {std::string("arena:\n\tsize: 2\n"), std::string("arena:\n  size: 2\n  \twall_height: 1\n"),
        std::string("arena: {size: 2}\nmodels:\n\t- model: bot.yaml\n")}) {
    const std::string message = LoadText(world);
    EXPECT_NE(message.find("world.yaml:"), std::string::npos) << message;
    EXPECT_NE(message.find("YAML syntax error: "), std::string::npos) << message;
    EXPECT_NE(message.find(hint), std::string::npos) << message;
  }
  // In a model file too.
  Write("bot.yaml", "model: bot\nobjects:\n  type: dummy\n\tname: x\n");
  std::string message = LoadText(std::string("arena: {size: 2}\n") + kModels);
  EXPECT_NE(message.find("bot.yaml:4:"), std::string::npos) << message;
  EXPECT_NE(message.find(hint), std::string::npos) << message;
  // Not for other syntax errors, nor for a tab that is not indentation.
  message = LoadText("arena: {size: [1,\t2}\n");
  EXPECT_NE(message.find("YAML syntax error"), std::string::npos) << message;
  EXPECT_EQ(message.find(hint), std::string::npos) << message;
}

TEST_F(MalformedWorldTest, MissingWorldFileIsNamed) {
  const std::string message = ErrorOf([&] { Load(dir_ / "nothere.yaml"); });
  EXPECT_NE(message.find("nothere.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
}

TEST_F(MalformedWorldTest, DefaultBackendMustExist) {
  // A registry without "box2d": a world that names no backend says so.
  ModuleRegistry registry;
  registry.RegisterDynamics({"", "ode", "1", "test double"}, {},
                            [] { return std::make_unique<testing::NullDynamics>(); });
  const fs::path file = Write("world.yaml", "arena: {size: 2}\n");
  const std::string message = ErrorOf([&] { LoadWorld(file, {}, registry); });
  EXPECT_NE(message.find("box2d"), std::string::npos) << message;
  EXPECT_NE(message.find("world.yaml"), std::string::npos) << message;
}

TEST_F(MalformedWorldTest, GarbageNeverCrashes) {
  std::string deep(5000, '[');
  std::string deep_map;
  for (int i = 0; i < 3000; ++i) deep_map += "{a: ";
  const std::vector<std::string> inputs = {
      "",
      "42",
      "just some text",
      "[1, 2, 3]",
      "- a\n- b\n",
      std::string("\x00\x01\x02\xff\xfe\x80{[:", 9),
      "\xef\xbb\xbf\xc3\x28 arena: {size: 2}",
      deep,
      deep_map,
      "arena: &a {size: *a}\n",
      "simulation: {time_step: 1e999}\n",
      "simulation: {time_step: -0}\n",
      "simulation: {seed: 99999999999999999999999}\n",
      "simulation: {steps: 1e300}\n",
      "simulation: {physics_substeps: .inf}\n",
      "simulation: [1, 2]\n",
      "parameters: {robots: [1, 2]}\n",
      "parameters: {end: 1}\n",
      "parameters: 5\n",
      "arena: {size: [1, 2, 3]}\n",
      "arena: {size: [-1, 2]}\n",
      "arena: {size: {a: 1}}\n",
      "arena: {size: ~}\n",
      "arena: {size: '='}\n",
      "arena: {size: '= nil'}\n",
      "arena: {size: '= {}'}\n",
      "arena: {size: '= 1/0'}\n",
      "arena: {size: '= 0/0'}\n",
      "arena: {size: '= (\"x\"):rep(1e9)'}\n",
      "arena: {size: '= (function(s) while true do s = s .. s end end)(\"xx\")'}\n",
      "arena: {size: '= (function f() return f() + 1 end)()'}\n",
      "arena: {size: '$'}\n",
      "obstacles: {a: 1}\n",
      "obstacles: [5]\n",
      "obstacles: [{shape: box}]\n",
      "obstacles: [{shape: box, size: [1, 1, 1], position: [1e308, 0, 0]}]\n",
      // Names no path finds (they loaded: sim.getObject('/a/b') found nothing).
      "obstacles: [{name: a/b, shape: box, size: [1, 1, 1]}]\n",
      "obstacles: [{name: '', shape: box, size: [1, 1, 1]}]\n",
      "obstacles: [{name: 'x[0]', shape: box, size: [1, 1, 1]}]\n",
      "obstacles: [{name: 'a b', shape: box, size: [1, 1, 1]}]\n",
      // A quote left open, a second document.
      "parameters:\n  robots: 'abc\narena:\n  size: 3\n",
      "arena: {size: 3}\n---\nbogus_key: 1\n",
      "models: 7\n",
      "models: [[]]\n",
      "models: [{model: [a]}]\n",
      "models: [{model: ../../../../../../../../../../dev/null, count: 1, distribute: {}}]\n",
      "models: [{model: /, count: 1, distribute: {}}]\n",
      "models: [{model: /dev/zero, count: 1, distribute: {}}]\n",
      "arena: {size: 2}\nmodels: [{model: bot.yaml, count: 1e12, distribute: {}}]\n",
      "arena: {size: 2}\nmodels: [{model: bot.yaml, count: -1, distribute: {}}]\n",
      "arena: {size: 2}\nmodels: [{model: bot.yaml, position: [.nan, 0]}]\n",
      "arena: {size: 2}\nmodels: [{model: bot.yaml, count: 2, distribute: {region: {min: [1, 1], "
      "max: [0, 0]}}}]\n",
      "metrics: [{name: [x]}]\n",
      "metrics: [{name: mean_nearest_neighbor_distance, every: 0}]\n",
  };
  for (const std::string& input : inputs) {
    const std::string message = LoadText(input);
    EXPECT_EQ(message.find("NOT A swarmsim::Error"), std::string::npos) << input.substr(0, 80);
    EXPECT_EQ(message.find("NO ERROR"), std::string::npos) << input.substr(0, 80);
    // The world file, or the model file it names.
    EXPECT_TRUE(message.find("world.yaml") != std::string::npos ||
                message.find("/dev/null") != std::string::npos ||
                message.find("model file '/") != std::string::npos)
        << message;
  }
  // Garbage model files too (a cycle of aliases in the object tree included).
  const std::vector<std::string> models = {
      "",
      "model: bot\n",
      "model: bot\nobjects: []\n",
      "model: bot\nobjects: [{type: dummy}, {type: dummy}]\n",
      "model: bot\nobjects: &r {type: dummy, children: [*r]}\n",
      "model: bot\nobjects: &r {type: dummy, children: [{name: a, type: dummy, children: [*r]}]}\n",
      "model: 'bad name#'\nobjects: {type: dummy}\n",
      "model: bot\nparameters: {x: [1]}\nobjects: {type: dummy}\n",
      "model: bot\nobjects: {type: proximity_ring, count: 4, radius: 1}\n",
      "model: bot\nobjects: {type: dummy, children: [{type: proximity_ring, name: p, count: 1e9, "
      "radius: 1}]}\n",
      "model: bot\nobjects: {type: dummy, children: [{type: dummy, name: 'a/b'}]}\n",
      "model: bot\nobjects: {type: joint, joint: hinge}\n",
      "model: bot\nobjects: {type: shape, shape: box, size: [1, 1, 1], script: ''}\n",
      "model: bot\nobjects: {type: shape, shape: box, size: [1, 1, 1], script: .}\n",
  };
  for (const std::string& model : models) {
    Write("bot.yaml", model);
    const std::string message = LoadText(std::string("arena: {size: 2}\n") + kModels);
    EXPECT_EQ(message.find("NOT A swarmsim::Error"), std::string::npos) << model;
    EXPECT_EQ(message.find("NO ERROR"), std::string::npos) << model;
    EXPECT_NE(message.find("bot.yaml"), std::string::npos) << message;
  }
}

// Random edits of the example world and model: each load either succeeds or
// throws swarmsim::Error, never anything else.
TEST_F(MalformedWorldTest, MutatedExamplesNeverCrash) {
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string world = read(kDiffusion);
  const std::string model = read(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/models/footbot.yaml");
  // The same layout as the repository: worlds/, worlds/models/, scripts/.
  fs::create_directories(dir_ / "worlds" / "models");
  fs::create_directories(dir_ / "scripts");
  Write("scripts/diffusion.lua", "-- test\n");
  const std::string alphabet = ":-[]{}$=#'\"&*!|>%@ \t\n,.0123456789eaz";
  Rng rng(42, 0);
  auto mutate = [&](std::string text) {
    const int edits = static_cast<int>(rng.UniformInt(1, 3));
    for (int e = 0; e < edits && !text.empty(); ++e) {
      const size_t at = static_cast<size_t>(rng.UniformInt(0, int64_t(text.size()) - 1));
      switch (rng.UniformInt(0, 3)) {
        case 0: text[at] = alphabet[rng.UniformInt(0, int64_t(alphabet.size()) - 1)]; break;
        case 1: text.erase(at, static_cast<size_t>(rng.UniformInt(1, 20))); break;
        case 2:
          text.insert(at, 1, alphabet[rng.UniformInt(0, int64_t(alphabet.size()) - 1)]);
          break;
        case 3: text.resize(at); break;
      }
    }
    return text;
  };
  LoadOptions options;
  options.overrides = {{"robots", "20"}};
  int loaded = 0, errors = 0;
  for (int i = 0; i < 400; ++i) {
    const bool world_edit = i % 2 == 0;
    Write("worlds/world.yaml", world_edit ? mutate(world) : world);
    Write("worlds/models/footbot.yaml", world_edit ? model : mutate(model));
    const std::string message = ErrorOf([&] { Load(dir_ / "worlds" / "world.yaml", options); });
    ASSERT_EQ(message.find("NOT A swarmsim::Error"), std::string::npos) << message;
    (message == "NO ERROR" ? loaded : errors)++;
  }
  EXPECT_GT(errors, 100);
  EXPECT_GT(loaded, 10);
}

TEST_F(MalformedWorldTest, ExpressionsSeeParametersAndMath) {
  const fs::path file =
      Write("world.yaml",
            "parameters:\n  robots: 8\n  side: '= 2 * math.sqrt(robots / 2) + floor(pi)'\n"
            "arena: {size: [$side, '= side / 2']}\n"
            "simulation: {duration: '= robots', time_step: 0.5}\n");
  LoadedWorld loaded = Load(file);
  EXPECT_DOUBLE_EQ(std::get<double>(loaded.world->parameters().at("side")), 7);
  EXPECT_EQ(*loaded.steps, 16);
  const Scene& scene = loaded.world->scene();
  EXPECT_NEAR(scene.shape(scene.FindObject("/wall_east")).size.y, 3.5, 1e-12);
  // An override of a parameter feeds the expressions that use it.
  LoadOptions options;
  options.overrides = {{"robots", "32"}};
  EXPECT_DOUBLE_EQ(std::get<double>(Load(file, options).world->parameters().at("side")), 11);
}

TEST_F(MalformedWorldTest, ParameterUsingOneBelowItSaysOnlyThoseAboveCanBeUsed) {
  const std::string rule = "a parameter can use only the parameters defined above it";
  // An expression and a $reference to a later parameter: named, with where it is.
  std::string message = LoadText("parameters:\n  a: \"= b * 2\"\n  b: 3\n");
  EXPECT_NE(message.find("world.yaml:2:6: in expression 'b * 2' for 'a': parameter 'b' is "
                         "defined below this one (at line 3); " +
                         rule),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find("there are no parameters"), std::string::npos) << message;
  message = LoadText("parameters:\n  x: 1\n  a: $b\n  b: 3\n");
  EXPECT_NE(message.find("world.yaml:3:6: 'a': parameter 'b' is defined below this one "
                         "(at line 4); " +
                         rule),
            std::string::npos)
      << message;
  // An unknown name lists the parameters above; none above is not "none at all".
  message = LoadText("parameters:\n  a: \"= zzz\"\n  b: 3\n");
  EXPECT_NE(message.find("unknown name 'zzz' (no parameters are defined above this one)"),
            std::string::npos)
      << message;
  message = LoadText("parameters:\n  x: 1\n  a: \"= zzz\"\n  b: 3\n");
  EXPECT_NE(message.find("unknown name 'zzz' (parameters defined above this one: x)"),
            std::string::npos)
      << message;
  message = LoadText("parameters:\n  a: \"= a + 1\"\n");
  EXPECT_NE(message.find("parameter 'a' cannot use itself (" + rule + ")"), std::string::npos)
      << message;
  // Outside 'parameters' every parameter is visible, and the message says so.
  message = LoadText("parameters:\n  x: 1\narena: {size: \"= zzz\"}\n");
  EXPECT_NE(message.find("unknown name 'zzz' (parameters: x)"), std::string::npos) << message;
}

TEST_F(MalformedWorldTest, ModelValuesUseModelParametersAndScriptsAreShared) {
  // The root as a one-element list, without a name; a parameter shadowing a
  // world one; one script file on two objects.
  Write("bot.yaml",
        "model: bot\n"
        "parameters: {r: 0.1, side: {default: '= 2 * size', unit: m}}\n"
        "objects:\n"
        "  - type: shape\n"
        "    shape: cylinder\n"
        "    radius: $r\n"
        "    height: '= r / 2'\n"
        "    script: bot.lua\n"
        "    children:\n"
        "      - {name: arm, type: dummy, position: [$side, 0, 0], script: ./bot.lua}\n");
  const fs::path file = Write("world.yaml",
                              "parameters: {size: 0.3, r: 7}\n"
                              "arena: {size: 3}\n"
                              "models:\n"
                              "  - {model: bot.yaml, count: 2, distribute: {},"
                              " parameters: {r: 0.2}}\n");
  LoadedWorld loaded = Load(file);
  const Scene& scene = loaded.world->scene();
  ASSERT_EQ(loaded.world->robot_count(), 2);
  const ObjectId root = scene.instance(1).root;
  EXPECT_EQ(scene.name(root), "bot#1");
  EXPECT_DOUBLE_EQ(scene.shape(root).size.x, 0.2);
  EXPECT_DOUBLE_EQ(scene.shape(root).size.z, 0.1);
  EXPECT_NEAR(scene.world_pose(root).p.z, 0.05, 1e-12);
  const ObjectId arm = scene.FindObject("./arm", root);
  ASSERT_FALSE(arm.IsNull());
  EXPECT_NEAR((scene.world_pose(root).Inverse() * scene.world_pose(arm)).p.x, 0.6, 1e-12);
  EXPECT_EQ(scene.script(arm)->source.get(), scene.script(root)->source.get());
  EXPECT_EQ(std::get<double>(*loaded.world->FindParameter(0, "r")), 0.2);
  EXPECT_EQ(std::get<double>(loaded.world->parameters().at("r")), 7);
}

TEST_F(MalformedWorldTest, SinglePlacedCopiesAndObstacles) {
  const fs::path file = Write(
      "world.yaml",
      "arena: {size: 4}\n"
      "obstacles:\n"
      "  - {name: crate, shape: box, size: [0.6, 0.3, 0.2], position: [1, 1, 0.1], heading_deg: "
      "30}\n"
      "  - {shape: cylinder, radius: 0.25, height: 0.2, position: [-1, -1, 0.1]}\n"
      "models:\n"
      "  - {model: bot.yaml, position: [0.5, -0.5], heading_deg: 90, parameters: {speed: 0.2}}\n"
      "  - {model: bot.yaml, count: 5, distribute: {clearance: 0.1}}\n");
  LoadedWorld loaded = Load(file);
  const World& world = *loaded.world;
  const Scene& scene = world.scene();
  ASSERT_EQ(world.robot_count(), 6);
  const Pose X = scene.world_pose(scene.instance(0).root);
  ExpectNear(X.p, {0.5, -0.5, 0.025});
  EXPECT_NEAR(X.q.Yaw(), M_PI / 2, 1e-12);
  EXPECT_EQ(Get(world, 0, "speed"), 0.2);
  EXPECT_EQ(Get(world, 1, "speed"), 0.05);
  // Entries have their own parameter sets; copies of one entry share theirs.
  EXPECT_NE(world.FindParameter(0, "speed"), world.FindParameter(1, "speed"));
  EXPECT_EQ(world.FindParameter(1, "speed"), world.FindParameter(5, "speed"));
  const ObjectId crate = scene.FindObject("/crate");
  ASSERT_FALSE(crate.IsNull());
  EXPECT_NEAR(scene.world_pose(crate).q.Yaw(), M_PI / 6, 1e-12);
  EXPECT_FALSE(scene.FindObject("/obstacle_1").IsNull());
  // A copy placed on an obstacle is an error.
  const fs::path bad = Write("bad.yaml",
                             "obstacles: [{shape: cylinder, radius: 0.5, height: 0.2}]\n"
                             "models: [{model: bot.yaml, position: [0.2, 0]}]\n");
  const std::string message = ErrorOf([&] { Load(bad); });
  EXPECT_NE(message.find("bad.yaml:2:38:"), std::string::npos) << message;
  EXPECT_NE(message.find("overlaps"), std::string::npos) << message;
}

}  // namespace
}  // namespace swarmsim
