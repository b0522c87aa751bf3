// modules/environment registers the `octomap` map format of a world's
// `environment:` key, every key of it documented in worlds/README.md.
#include "modules/environment/environment.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "framework/registry.h"
#include "framework/world_section.h"

namespace swarmsim {
namespace {

TEST(EnvironmentModuleTest, RegistersTheOctomapFormatWithItsDocumentedKeys) {
  ModuleRegistry registry;
  environment::Register(&registry);
  ASSERT_EQ(registry.environment_formats().size(), 1u);
  const EnvironmentFormatDescriptor& format = *registry.environment_formats()[0];
  EXPECT_EQ(format.key, "octomap");
  ASSERT_TRUE(format.read);
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream readme;
  readme << in.rdbuf();
  ASSERT_FALSE(readme.str().empty());
  EXPECT_NE(readme.str().find("`octomap`"), std::string::npos);
  size_t keys = 0;
  for (const ObjectKey& key : format.keys) {
    ++keys;
    EXPECT_NE(readme.str().find("| `" + std::string(key.name) + "` |"), std::string::npos)
        << key.name << " is not in worlds/README.md's environment table";
  }
  EXPECT_EQ(keys, 4u);  // offset, z_range, occupancy_threshold, max_memory_mb
}

}  // namespace
}  // namespace swarmsim
