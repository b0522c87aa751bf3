// The world file's `environment:` key (swarm/loader/environment.cc): its keys
// checked, and a map file that cannot be read is an error at the key's
// file:line:column, through the loader and the program.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/number_rule.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "framework/world_section.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"
#include "tests/framework/error_of.h"
#include "tests/shared_maps.h"
#include "tests/swarm/run_program.h"

namespace swarmsim {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::FreshTempDir;
using testing::RunProgram;

LoadedWorld Load(const fs::path& file, LoadOptions options) {
  static const ModuleRegistry registry = [] {
    ModuleRegistry r;
    RegisterBuiltinModules(&r);
    return r;
  }();
  LoadedWorld loaded = LoadWorld(file, options, registry);
  loaded.world->set_log_sink([](std::string_view) {});
  return loaded;
}

// A world naming `map_file` (written into its folder with `bytes`, unless empty).
fs::path MapWorld(const std::string& name, const std::string& map_file, const std::string& bytes) {
  const fs::path dir = FreshTempDir("swarmsim_env", name);
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: box2d, steps: 1}\n"
                                       "environment:\n"
                                       "  octomap: "
                                    << map_file << "\n";
  if (!bytes.empty()) std::ofstream(dir / map_file, std::ios::binary) << bytes;
  return dir;
}

TEST(EnvironmentWorldTest, BadMapFilesAreErrorsAtTheWorldKeyThroughTheProgram) {
  std::string whole;
  const std::string map = testing::SharedMap("geb079.bt");
  if (!map.empty()) {
    std::ifstream in(map, std::ios::binary);
    whole.assign(std::istreambuf_iterator<char>(in), {});
  } else {  // a small stand-in: a header promising more than its body holds
    whole = "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n";
    whole += std::string(8, '\xff');
  }
  struct Case {
    std::string name, file, bytes, expect;
  };
  const Case cases[] = {
      {"truncated", "cut.bt", whole.substr(0, whole.size() * 2 / 3), "octomap cut.bt: truncated"},
      {"header", "plain.bt", "just text\n", "octomap plain.bt: not an OctoMap file"},
      {"missing", "nowhere.bt", "", "octomap nowhere.bt: no such file"},
  };
  for (const Case& c : cases) {
    const fs::path dir = MapWorld(c.name, c.file, c.bytes);
    const auto r = RunProgram("run " + (dir / "world.yaml").string() + " --quiet");
    EXPECT_NE(r.exit_code, 0) << c.name;
    EXPECT_LT(r.exit_code, 128) << c.name << ": not a crash\n" << r.output;
    EXPECT_CONTAINS(r.output, "world.yaml:3:12: " + c.expect);
    fs::remove_all(dir);
  }
}

TEST(EnvironmentWorldTest, EnvironmentKeysAreChecked) {
  const fs::path dir = MapWorld("keys", "x.bt", "");
  std::ofstream(dir / "world.yaml") << "environment: {octomap: x.bt, z_rnage: [0, 1]}\n";
  EXPECT_CONTAINS(ErrorOf([&] { Load(dir / "world.yaml", {}); }),
                  "unknown key 'z_rnage' in 'environment'; did you mean 'z_range'?");
  std::ofstream(dir / "world.yaml") << "environment: {octomap: x.bt, z_range: [1, 0]}\n";
  EXPECT_CONTAINS(ErrorOf([&] { Load(dir / "world.yaml", {}); }), "min <= max");
  std::ofstream(dir / "world.yaml") << "environment: {offset: [0, 0, 0]}\n";
  EXPECT_CONTAINS(ErrorOf([&] { Load(dir / "world.yaml", {}); }), "'octomap' is required");
  fs::remove_all(dir);
}

TEST(EnvironmentWorldTest, EnvironmentValuesSayWhatTheyExpectAtTheirKey) {
  const fs::path dir = MapWorld("values", "x.bt", "");
  const auto error = [&](const std::string& environment) {
    std::ofstream(dir / "world.yaml") << "environment: " << environment << "\n";
    return ErrorOf([&] { Load(dir / "world.yaml", {}); });
  };
  EXPECT_CONTAINS(error("maps/x.bt"),
                  "world.yaml:1:14: 'environment' must be a mapping such as "
                  "{octomap: maps/building.bt} (got \"maps/x.bt\")");
  EXPECT_CONTAINS(error("{octomap: ''}"), "'octomap' must be the path of a .bt or .ot file");
  EXPECT_CONTAINS(error("{octomap: x.bt, occupancy_threshold: 0}"),
                  "world.yaml:1:51: 'occupancy_threshold' must be a probability between 0 and 1 "
                  "(exclusive) (got \"0\")");
  EXPECT_CONTAINS(error("{octomap: x.bt, max_memory_mb: 0}"), "a positive number of MiB");
  EXPECT_CONTAINS(error("{octomap: x.bt, offset: [0, 0]}"), "offset");
  // Every value is checked before the map is read: a missing map comes last.
  EXPECT_CONTAINS(error("{octomap: x.bt, z_range: [0, 1]}"), "world.yaml:1:24: octomap x.bt: ");
  EXPECT_EQ(error("").find("environment"), std::string::npos) << "no environment: no map";
  fs::remove_all(dir);
}

// A map format is the registry's: one a module (here, this test) registers
// is read by the loader with its own keys, no loader change; a mapping
// naming two formats, or none, says which there are.
TEST(EnvironmentFormatTest, ARegisteredFormatIsReadThroughTheLoader) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  static constexpr ObjectKey kKeys[] = {{"height", "1", "m, of the one box"}};
  auto format = std::make_shared<EnvironmentFormatDescriptor>();
  format->key = "one_box";
  format->doc = "a test format: one box, 1 m a side, standing at the origin";
  format->keys = kKeys;
  format->read = [](const ObjectReader& r, const fs::path& folder, std::vector<std::string>*) {
    EXPECT_EQ(r.String("one_box"), "anything.box");
    EXPECT_FALSE(folder.empty());
    auto map = std::make_shared<EnvironmentMap>();
    map->source = "anything.box";
    map->resolution = 1;
    const double h = r.Has("height") ? r.Number("height", kCoordinate) : 1;
    map->boxes.push_back({{-0.5, -0.5, 0}, {0.5, 0.5, h}});
    map->lo = map->boxes[0].lo;
    map->hi = map->boxes[0].hi;
    return std::shared_ptr<const EnvironmentMap>(std::move(map));
  };
  registry.RegisterEnvironmentFormat(format);
  EXPECT_CONTAINS(ErrorOf([&] { registry.RegisterEnvironmentFormat(format); }),
                  "environment map format 'one_box' is registered twice");

  const fs::path dir = FreshTempDir("swarmsim_env", "format");
  fs::create_directories(dir);
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic}\n"
                                       "environment: {one_box: anything.box, height: 2}\n";
  LoadedWorld w = LoadWorld(dir / "world.yaml", {}, registry);
  const EnvironmentMap* map = w.world->scene().environment();
  ASSERT_NE(map, nullptr);
  ASSERT_EQ(map->boxes.size(), 1u);
  EXPECT_EQ(map->boxes[0].hi.z, 2);

  std::ofstream(dir / "world.yaml") << "environment: {one_box: a.box, octomap: b.bt}\n";
  EXPECT_CONTAINS(ErrorOf([&] { LoadWorld(dir / "world.yaml", {}, registry); }),
                  "'environment' names one map: 'octomap' or 'one_box', not both");
  std::ofstream(dir / "world.yaml") << "environment: {hight: 2}\n";
  EXPECT_CONTAINS(
      ErrorOf([&] { LoadWorld(dir / "world.yaml", {}, registry); }),
      "world.yaml:1:14: 'environment' needs the map file under one of: octomap, one_box");
  // The octomap format's keys are not this one's.
  std::ofstream(dir / "world.yaml") << "environment: {one_box: a.box, z_range: [0, 1]}\n";
  EXPECT_CONTAINS(ErrorOf([&] { LoadWorld(dir / "world.yaml", {}, registry); }), "z_range");
  // This format cannot list its occupied cells (no occupied_plane): robots
  // placed beside its map are placed as if it were not there, and the user
  // is told so.
  std::ofstream(dir / "world.yaml") << "simulation: {physics: kinematic}\n"
                                       "arena: {size: 4}\n"
                                       "environment: {one_box: anything.box}\n"
                                       "models:\n"
                                       "  - {model: " SWARMSIM_SOURCE_DIR
                                       "/worlds/models/footbot.yaml, count: 2,\n"
                                       "     distribute: {region: arena, clearance: 0.05}}\n";
  const LoadedWorld placed = LoadWorld(dir / "world.yaml", {}, registry);
  ASSERT_EQ(placed.warnings.size(), 1u);
  EXPECT_CONTAINS(placed.warnings[0],
                  "format 'one_box' cannot list its occupied cells: placement does not keep "
                  "robots clear of the map");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmsim
