// YAML files for the tests of the loader's own readers (yaml.cc, values.cc,
// object_reader.cc): written to a folder of this process's own and loaded.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "framework/error.h"
#include "swarm/loader/yaml.h"

namespace swarmsim::loader::testing {

namespace fs = std::filesystem;

inline fs::path YamlDir() {
  const fs::path dir =
      fs::temp_directory_path() / ("swarmsim_yaml_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// `text` as YamlDir()/`name`, loaded as a world file.
inline YamlFile Yaml(const std::string& text, const std::string& name = "w.yaml") {
  std::ofstream(YamlDir() / name) << text;
  return YamlFile::Load(YamlDir() / name, "world file", "", name);
}

// The file's root as a field named `name`.
inline Field Root(const YamlFile& file, const std::string& name = "root") {
  return {name, file.root(), file.root().Mark(), file.root().Mark()};
}

// What `f` throws ("" when nothing).
inline std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace swarmsim::loader::testing
