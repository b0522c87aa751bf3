// Top-level world-file sections that modules own (framework/world_section.h):
// the loader hands every key it does not know itself to the registered
// sections (metrics:, paint:), an unknown key still suggests them, and
// worlds/README.md documents each section and its keys. The sections' own
// tests: tests/modules/paint/paint_section_test.cc,
// tests/modules/metrics/metrics_section_test.cc.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "framework/world_section.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

class WorldSectionsTest : public testing::WorldDirTest {
 protected:
  // The loader's message for `world_text`, or "(no error)".
  std::string ErrorOfWorld(const std::string& world_text) {
    try {
      Load(world_text);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }
};

void ExpectHas(const std::string& message, const std::vector<std::string>& fragments) {
  for (const std::string& fragment : fragments)
    EXPECT_NE(message.find(fragment), std::string::npos)
        << "expected '" << fragment << "' in: " << message;
}

TEST_F(WorldSectionsTest, WorldsReadmeDocumentsEverySectionAndItsKeys) {
  std::ifstream in(std::string(SWARMSIM_SOURCE_DIR) + "/worlds/README.md");
  std::stringstream s;
  s << in.rdbuf();
  const std::string readme = s.str();
  const size_t keys_line = readme.find("Keys: `simulation`");
  ASSERT_NE(keys_line, std::string::npos);
  const std::string keys = readme.substr(keys_line, readme.find("\n\n", keys_line) - keys_line);
  ASSERT_GE(registry_.world_sections().size(), 2u);
  for (const auto& section : registry_.world_sections()) {
    EXPECT_FALSE(section->doc.empty()) << section->key;
    EXPECT_NE(keys.find("`" + section->key + "`"), std::string::npos)
        << section->key << " is not among the top-level keys of worlds/README.md";
    const size_t at = readme.find("\n### `" + section->key + "`\n");
    ASSERT_NE(at, std::string::npos) << "no '### `" << section->key << "`' in worlds/README.md";
    const std::string text = readme.substr(at, readme.find("\n### ", at + 1) - at);
    for (const ObjectKey& key : section->keys) {
      const std::string row = std::string("| `") + key.name + "` |";
      EXPECT_NE(text.find(row), std::string::npos) << section->key << ": no " << row;
      EXPECT_NE(key.doc, nullptr);
      EXPECT_NE(key.default_text, nullptr);
    }
  }
}

TEST_F(WorldSectionsTest, UnknownTopLevelKeySuggestsASection) {
  ExpectHas(ErrorOfWorld("arena: {size: 2}\npant: {resolution: 0.1}\n"),
            {"world.yaml:2:1:", "unknown key 'pant' in the world file", "did you mean 'paint'?"});
  ExpectHas(ErrorOfWorld("metric: [covered_area]\n"),
            {"world.yaml:1:1:", "unknown key 'metric'", "did you mean 'metrics'?"});
}

}  // namespace
}  // namespace swarmsim
