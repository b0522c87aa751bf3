// A World built in code with the built-in modules, for the modules' tests:
// objects added through the Scene (a module's own types through their
// rows), scripts attached from strings, what the scripts print kept, and
// the error a start or step throws caught.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "framework/error.h"
#include "framework/registry.h"
#include "framework/scene.h"
#include "framework/world.h"
#include "modules/builtin.h"
#include "tests/framework/error_of.h"
#include "tests/modules/entry_reader.h"

namespace swarmsim::testing {

class ModuleWorld {
 public:
  // Kinematic physics by default: nothing moves unless a module moves it.
  // `script_memory_limit`: bytes (simulation.script_memory_mb), -1: the default.
  explicit ModuleWorld(std::string physics = "kinematic", int threads = 1, double time_step = 0.1,
                       int64_t script_memory_limit = -1) {
    RegisterBuiltinModules(&registry_);
    WorldSettings settings;
    settings.physics = std::move(physics);
    settings.threads = threads;
    settings.time_step = time_step;
    if (script_memory_limit >= 0) settings.script_memory_limit = script_memory_limit;
    world_ = std::make_unique<World>(settings, registry_);
    world_->set_log_sink([this](std::string_view line) { log_.emplace_back(line); });
  }
  World& world() { return *world_; }
  Scene& scene() { return world_->scene(); }
  const std::vector<std::string>& log() const { return log_; }

  // An object of the type named `type_name` with `row` (a default row if null).
  template <typename Row>
  ObjectId Add(std::string_view type_name, std::string name, ObjectId parent, const Pose& X_PO,
               const Row* row) {
    return scene().AddObject(TypeNamed(scene(), type_name), std::move(name), parent, X_PO, row);
  }
  template <typename Row>
  Row& RowOf(std::string_view type_name, ObjectId id) {
    return testing::RowOf<Row>(&scene(), type_name, id);
  }
  // A box shape of full extents `size` at X_PO.
  ObjectId Box(std::string name, ObjectId parent, const Pose& X_PO, const Vec3& size,
               bool dynamic = false) {
    ShapeData s;
    s.kind = ShapeKind::kBox;
    s.size = size;
    s.dynamic = dynamic;
    return scene().AddShape(std::move(name), parent, X_PO, s);
  }
  // A robot: a model instance rooted at a dummy at X_WR.
  ObjectId Robot(const std::string& name, const Pose& X_WR) {
    const ObjectId root = scene().AddDummy(name, {}, X_WR);
    scene().MakeModelInstance(root, "bot", name);
    return root;
  }
  void Script(ObjectId on, const std::string& code, const std::string& file = "script.lua") {
    scene().AttachScript(on, std::make_shared<const ScriptSource>(ScriptSource{file, code}));
  }
  // Starts the world and runs `steps` steps; the message of the error
  // thrown, or "".
  std::string Run(int steps) {
    try {
      if (!world_->started()) world_->Start();
      for (int i = 0; i < steps; ++i) world_->Step();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  }

 private:
  ModuleRegistry registry_;
  std::unique_ptr<World> world_;
  std::vector<std::string> log_;
};

// A fresh folder for a test's files, removed with it.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("swarmsim_modules_" + std::to_string(::getpid()) + "_" + std::to_string(counter_++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

// A whole file's bytes ("" if it cannot be read).
inline std::string ReadFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace swarmsim::testing
