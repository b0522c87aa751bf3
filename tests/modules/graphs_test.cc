// The graph object type as the registry holds it: its keys are documented
// in worlds/README.md (and listed in the `type` row), and the module is
// registered with every world.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "framework/module.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "modules/builtin.h"

namespace swarmsim {
namespace {

TEST(GraphsTest, WorldsReadmeDocumentsEveryKey) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream s;
  s << in.rdbuf();
  const std::string readme = s.str();
  const size_t type_row = readme.find("| `type` | required |");
  ASSERT_NE(type_row, std::string::npos);
  EXPECT_NE(readme.substr(type_row, readme.find('\n', type_row) - type_row).find("`graph`"),
            std::string::npos);
  const ObjectTypeDescriptor* graph = nullptr;
  for (const ObjectTypeDescriptor* type : registry.object_types())
    if (std::string(type->name) == "graph") graph = type;
  ASSERT_NE(graph, nullptr);
  const size_t section = readme.find("\n#### graph\n");
  ASSERT_NE(section, std::string::npos);
  const std::string text = readme.substr(section, readme.find("\n#### ", section + 1) - section);
  for (const ObjectKey& key : graph->keys)
    EXPECT_NE(text.find(std::string("| `") + key.name + "` |"), std::string::npos) << key.name;
  // Every stream kind has its row, and the Lua calls are there.
  for (const char* kind : {"position", "orientation", "velocity", "angular_velocity", "joint",
                           "joint_velocity", "proximity", "force", "distance", "script"})
    EXPECT_NE(text.find(std::string("| `") + kind + "`"), std::string::npos) << kind;
  EXPECT_NE(text.find("sim.setGraphStreamValue(h, name, value)"), std::string::npos);
  EXPECT_NE(text.find("sim.addGraphStream(h, name)"), std::string::npos);
  EXPECT_NE(text.find("sim.getGraphStreamValues(h, stream [, count])"), std::string::npos);
  // Every world gets the module (it samples after the others in the record phase).
  const ModuleDescriptor* module = registry.FindModule("graphs");
  ASSERT_NE(module, nullptr);
  EXPECT_TRUE(module->every_world);
  EXPECT_EQ(module->phases, PhaseBit(ModulePhase::kRecord));
}

}  // namespace
}  // namespace swarmsim
