// The object types the built-in modules register (distance, collision,
// mill, cuttable, graph, ...): worlds/README.md names each in the `type`
// row and documents every key in its "#### name" section, with its default
// (as the descriptor gives it, in backticks or not), so the docs cannot
// drift from the loader. (tests/framework/object_types_test.cc: the
// built-in types.)
#include "modules/builtin.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "framework/object_type.h"
#include "framework/registry.h"

namespace swarmsim {
namespace {

TEST(ModuleTypesTest, WorldsReadmeDocumentsEveryKeyOfEveryRegisteredType) {
  ModuleRegistry registry;
  RegisterBuiltinModules(&registry);
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream s;
  s << in.rdbuf();
  const std::string readme = s.str();
  const size_t type_row = readme.find("| `type` | required |");
  ASSERT_NE(type_row, std::string::npos);
  const std::string row = readme.substr(type_row, readme.find('\n', type_row) - type_row);
  ASSERT_FALSE(registry.object_types().empty());
  for (const ObjectTypeDescriptor* type : registry.object_types()) {
    const std::string name = type->name;
    EXPECT_NE(row.find("`" + name + "`"), std::string::npos) << name << " not in the type row";
    const size_t section = readme.find("\n#### " + name + "\n");
    ASSERT_NE(section, std::string::npos) << "no '#### " << name << "' in worlds/README.md";
    const std::string text = readme.substr(section, readme.find("\n#### ", section + 1) - section);
    for (const ObjectKey& key : type->keys) {
      const std::string cell = std::string("| `") + key.name + "` | ";
      EXPECT_TRUE(text.find(cell + "`" + key.default_text + "` |") != std::string::npos ||
                  text.find(cell + key.default_text + " |") != std::string::npos)
          << name << "." << key.name << " (default " << key.default_text
          << ") is not documented in worlds/README.md";
    }
  }
}

}  // namespace
}  // namespace swarmsim
