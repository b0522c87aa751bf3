// The fixture of loader tests that write world and model files: a registry
// of the built-in modules and a fresh folder per test
// (temp/swarmsim_<suite>_<test>_<pid>), removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "swarm/loader/world_loader.h"

namespace swarmsim::testing {

class WorldDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    RegisterBuiltinModules(&registry_);
    const ::testing::TestInfo& test = *::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("swarmsim_" + std::string(test.test_suite_name()) + "_" + test.name() + "_" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes `text` to dir_/name; returns the path.
  std::filesystem::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }

  // Loads `world_text` as dir_/world.yaml; the scripts' prints are dropped.
  LoadedWorld Load(const std::string& world_text, int threads = 1) {
    LoadOptions options;
    options.threads = threads;
    LoadedWorld w = LoadWorld(Write("world.yaml", world_text), options, registry_);
    w.world->set_log_sink([](std::string_view) {});
    return w;
  }
  // The loader's message for a model (thing.yaml) whose root is of `type`
  // and carries `keys` (indented lines), or "(no error)".
  std::string ErrorOf(const std::string& type, const std::string& keys) {
    Write("thing.yaml", "model: thing\nobjects:\n  type: " + type + "\n" + keys);
    try {
      Load(
          "simulation: {physics: kinematic}\nmodels: [{model: thing.yaml, position: [0, 0, 1]}]\n");
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
  // The row of the object at `path` (of the type's row type `Row`).
  template <typename Row>
  Row& RowOf(World& world, const std::string& path) {
    Scene& scene = world.scene();
    const ObjectId id = scene.FindObject(path);
    EXPECT_FALSE(id.IsNull()) << path;
    return *static_cast<Row*>(scene.row_data(id));
  }

  // worlds/README.md documents each of the registry's object types named
  // `types`: the `type` row lists it, and its `#### name` section has one
  // row per key, `| `key` | `default` |`.
  void ExpectDocumented(const std::vector<std::string>& types) const {
    std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
    std::stringstream s;
    s << in.rdbuf();
    const std::string readme = s.str();
    const size_t type_row = readme.find("| `type` | required |");
    ASSERT_NE(type_row, std::string::npos);
    const std::string row = readme.substr(type_row, readme.find('\n', type_row) - type_row);
    size_t found = 0;
    for (const ObjectTypeDescriptor* type : registry_.object_types()) {
      const std::string name = type->name;
      if (std::find(types.begin(), types.end(), name) == types.end()) continue;
      ++found;
      EXPECT_NE(row.find("`" + name + "`"), std::string::npos) << name;
      const size_t section = readme.find("\n#### " + name + "\n");
      ASSERT_NE(section, std::string::npos) << "no '#### " << name << "' in worlds/README.md";
      const std::string text =
          readme.substr(section, readme.find("\n#### ", section + 1) - section);
      for (const ObjectKey& key : type->keys) {
        const std::string line = std::string("| `") + key.name + "` | `" + key.default_text + "` |";
        EXPECT_NE(text.find(line), std::string::npos) << name << ": no " << line;
      }
    }
    EXPECT_EQ(found, types.size());
  }

  ModuleRegistry registry_;
  std::filesystem::path dir_;
};

}  // namespace swarmsim::testing
