// The fixture of loader tests that write world and model files: a registry
// of the built-in modules and a fresh folder per test
// (temp/swarmsim_<suite>_<test>_<pid>), removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "framework/registry.h"
#include "modules/builtin.h"

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

  ModuleRegistry registry_;
  std::filesystem::path dir_;
};

}  // namespace swarmsim::testing
