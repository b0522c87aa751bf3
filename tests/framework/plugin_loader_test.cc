// Loading plugins (framework/plugin_loader.cc): what a plugin registers
// reaches the registry; clear errors for a missing file, a library that is
// not a plugin, an ABI mismatch and a name registered twice.
#include "framework/plugin_loader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/world.h"
#include "tests/framework/error_of.h"
#include "tests/framework/fakes.h"

namespace swarmsim {
namespace {

std::string PluginPath(const std::string& name) {
  return (std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins" / name).string();
}

using testing::ErrorOf;

TEST(PluginTest, LoadErrorsNameThePathAndTheProblem) {
  ModuleRegistry registry;
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin("/nonexistent/p.so", &registry); }),
                  "cannot load plugin '/nonexistent/p.so': ");
  EXPECT_CONTAINS(
      ErrorOf([&] { LoadPlugin(PluginPath("wrong_abi_plugin.so"), &registry); }),
      "was built for plugin ABI version 9, this swarmsim has version 8 (and loads plugins "
      "of versions 6 to 8)");
  EXPECT_CONTAINS(
      ErrorOf([&] { LoadPlugin(PluginPath("old_abi_plugin.so"), &registry); }),
      "was built for plugin ABI version 3, this swarmsim has version 8 (and loads plugins "
      "of versions 6 to 8); rebuild it");
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin("libm.so.6", &registry); }), "cannot load plugin");
  LoadPlugin(PluginPath("example_plugin.so"), &registry);
  EXPECT_CONTAINS(ErrorOf([&] { LoadPlugin(PluginPath("example_plugin.so"), &registry); }),
                  "script command 'exampleSum' is registered twice");
}

}  // namespace
}  // namespace swarmsim
