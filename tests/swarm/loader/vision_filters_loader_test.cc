// Filter chains read from a model file (ObjectReader::Items through the
// loader): a valid chain runs, a plugin's element is found through the
// world's `plugins:`, and mistakes are errors at their file:line:column.
// Until a built-in type holds a chain, a test type (`filter_probe`, key
// `filters`) reads one the way the vision sensor will.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "framework/error.h"
#include "framework/object_type.h"
#include "framework/registry.h"
#include "framework/world.h"
#include "modules/rendering/filters/filters.h"
#include "swarm/loader/world_loader.h"
#include "tests/swarm/loader/world_dir_test.h"

namespace swarmsim {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

struct ProbeRow {
  filters::FilterChain chain;
};

constexpr ObjectKey kProbeKeys[] = {{"filters", "[]", "a filter chain (test)"}};

std::shared_ptr<const ObjectTypeDescriptor> ProbeType() {
  auto type = std::make_shared<ObjectTypeDescriptor>();
  type->name = "filter_probe";
  type->description = "holds a filter chain (test)";
  type->make_rows = [](const ObjectTypeDescriptor&) -> std::unique_ptr<RowTable> {
    return std::make_unique<Rows<ProbeRow>>();
  };
  type->keys = kProbeKeys;
  type->read = [](const ObjectTypeDescriptor&, const ObjectReader& reader, void* row) {
    static_cast<ProbeRow*>(row)->chain =
        filters::ParseFilterChain(reader, "filters", reader.registry());
  };
  return type;
}

// "line:column" (1-based) of the first `needle` in `text`.
std::string PositionOf(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  const size_t line_start = text.rfind('\n', at);
  const size_t line = 1 + std::count(text.begin(), text.begin() + static_cast<long>(at), '\n');
  const size_t column = at - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
  return std::to_string(line) + ":" + std::to_string(column);
}

class VisionFiltersLoaderTest : public testing::WorldDirTest {
 protected:
  void SetUp() override {
    WorldDirTest::SetUp();
    registry_.RegisterObjectType(ProbeType());
  }
  // A robot whose `cam` holds `filters` (YAML lines, indented by 8).
  std::string WriteModel(const std::string& filters, const std::string& plugins = "") {
    const std::string model =
        "model: bot\n"
        "objects:\n"
        "  name: body\n"
        "  type: dummy\n"
        "  children:\n"
        "    - name: cam\n"
        "      type: filter_probe\n"
        "      filters:\n" +
        filters;
    Write("bot.yaml", model);
    Write("world.yaml", "simulation: {physics: kinematic, time_step: 0.1}\n" + plugins +
                            "models:\n  - {model: bot.yaml, position: [0, 0]}\n");
    return model;
  }
  // The program's plugin folder is where a world finds `plugins: [example_plugin]`.
  LoadedWorld Load() {
    LoadOptions options;
    options.plugin_directories = {std::filesystem::path(SWARMSIM_BINARY).parent_path() / "plugins"};
    return LoadWorld(dir_ / "world.yaml", options, registry_);
  }
  std::string LoadError() {
    try {
      Load();
    } catch (const Error& e) {
      return e.what();
    }
    return "NO ERROR";
  }
  // The chain the loaded world's probe holds.
  static filters::FilterChain ChainOf(const LoadedWorld& loaded) {
    const Scene& scene = loaded.world->scene();
    ObjectType type;
    EXPECT_TRUE(scene.FindType("filter_probe", &type));
    const auto& rows = static_cast<const Rows<ProbeRow>&>(*scene.rows(type));
    EXPECT_EQ(rows.size(), 1u);
    return rows.rows.at(0).chain;
  }
};

TEST_F(VisionFiltersLoaderTest, AChainFromAModelFileRuns) {
  WriteModel(
      "        - {type: hsv_threshold, hue: [100, 140], saturation: [0.5, 1], value: [0.3, 1]}\n"
      "        - type: blobs\n"
      "          min_pixels: 2\n");
  const LoadedWorld loaded = Load();
  const filters::FilterChain chain = ChainOf(loaded);
  ASSERT_EQ(chain.size(), 2u);
  Image image;
  image.Resize(8, 8);
  for (int x = 2; x < 5; ++x) image.Pixel(x, 3)[1] = 200;  // a green bar
  image.Pixel(7, 7)[1] = 200;                              // too small
  const filters::FilterOutput out = chain.Run(image, {});
  ASSERT_EQ(out.blobs.size(), 1u);
  EXPECT_EQ(out.blobs[0].pixels, 3);
  EXPECT_DOUBLE_EQ(out.blobs[0].x, 3.5);
}

TEST_F(VisionFiltersLoaderTest, APluginsElementIsFoundThroughTheWorldsPlugins) {
  WriteModel("        - {type: invert}\n", "plugins: [example_plugin]\n");
  const LoadedWorld loaded = Load();
  Image image;
  image.Resize(2, 1);
  image.Pixel(0, 0)[0] = 10;
  const filters::FilterOutput out = ChainOf(loaded).Run(image, {});
  EXPECT_EQ(out.image.Pixel(0, 0)[0], 245);
  EXPECT_EQ(out.image.Pixel(1, 0)[2], 255);
  // Without the plugin: unknown.
  WriteModel("        - {type: invert}\n");
  EXPECT_CONTAINS(LoadError(), "'type' must be one of");
}

TEST_F(VisionFiltersLoaderTest, MistakesAreErrorsAtTheirFileLineAndColumn) {
  // An unknown element, with a suggestion.
  std::string model = WriteModel("        - {type: blob}\n");
  EXPECT_CONTAINS(LoadError(),
                  "bot.yaml:" + PositionOf(model, "blob}") + ": 'type' must be one of");
  EXPECT_CONTAINS(LoadError(), R"((got "blob"); did you mean 'blobs'?)");
  // Kinds that do not fit, at the element that needs another.
  model = WriteModel(
      "        - {type: grayscale}\n"
      "        - {type: blobs, min_pixels: 4}\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "blobs,") +
                                   ": 'blobs' needs a mask; 'grayscale' gives a grey image: put a "
                                   "threshold before it");
  // A bad value.
  model = WriteModel("        - {type: color_threshold, color: [1, 0, 2]}\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "2]"));
  model = WriteModel("        - {type: resize, width: 0, height: 4}\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "0,"));
  // A key the element does not take, with a suggestion and the item named.
  model = WriteModel(
      "        - {type: color_threshold, color: [1, 0, 0]}\n"
      "        - {type: blobs, min_pixel: 4}\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "min_pixel") +
                                   ": unknown key 'min_pixel' in filters[1] of object 'cam'; did "
                                   "you mean 'min_pixels'?");
  // A misspelt 'type'.
  model = WriteModel("        - {tpye: blobs}\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "tpye") +
                                   ": unknown key 'tpye' in filters[0] of object 'cam'; did you "
                                   "mean 'type'?");
  // An item that is not a map; a list that is not a list.
  model = WriteModel("        - blobs\n");
  EXPECT_CONTAINS(LoadError(), "bot.yaml:" + PositionOf(model, "blobs") +
                                   ": filters[0] of object 'cam' must be a mapping");
  model = WriteModel("          blobs\n");
  EXPECT_CONTAINS(LoadError(), "'filters' must be a list of maps");
}

}  // namespace
}  // namespace swarmsim
