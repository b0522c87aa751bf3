// The floor a world file draws (`floor:`, modules/floor) in the viewer page
// in headless Chromium: the recording carries it as its floor layer, and the
// page shows each region's colour where it lies.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/swarm/run_program.h"
#include "tests/swarm/viewer/browser.h"

namespace swarmsim::testing {
namespace {
namespace fs = std::filesystem;

TEST(ViewerFloorTest, ThePageShowsTheFloorWhereItLies) {
  if (const std::string missing = BrowserMissing(); !missing.empty()) GTEST_SKIP() << missing;
  const fs::path run = FreshTempDir("viewer_floor", "floor");
  const CommandResult result =
      RunProgram("run " + std::string(SWARMSIM_SOURCE_DIR) +
                 "/tests/data/viewer/floor/world.yaml --quiet --record --out " + run.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  ViewServer server(run.string(), (run / "server.log").string());
  ASSERT_FALSE(server.Address().empty()) << server.Output();
  Browser browser;
  browser.Open(server.Address());
  ASSERT_EQ(browser.WaitForViewer(), "");
  browser.Run("swarmsimViewer.topDown();");
  // Page pixels of points on the floor: the green half, the magenta half,
  // the black nest.
  const auto pixel_of = [&](double x, double y) {
    return browser.Run("return swarmsimViewer.project(" + std::to_string(x) + ", " +
                       std::to_string(y) + ", 0);");
  };
  const json green = pixel_of(-1, 0.5), magenta = pixel_of(1, 1.2), nest = pixel_of(1, 0);
  const Image image = browser.Screenshot();
  ASSERT_GT(image.width, 0);
  const auto at = [&](const json& p) {
    return image.At(static_cast<int>(p["x"].get<double>()), static_cast<int>(p["y"].get<double>()));
  };
  const uint8_t* g = at(green);
  const uint8_t* m = at(magenta);
  const uint8_t* n = at(nest);
  EXPECT_TRUE(g[1] > 100 && g[0] < g[1] / 2 && g[2] < g[1] / 2)
      << int(g[0]) << "," << int(g[1]) << "," << int(g[2]);
  EXPECT_TRUE(m[0] > 100 && m[2] > 100 && m[1] < m[0] / 2)
      << int(m[0]) << "," << int(m[1]) << "," << int(m[2]);
  EXPECT_TRUE(n[0] < 60 && n[1] < 60 && n[2] < 60)
      << int(n[0]) << "," << int(n[1]) << "," << int(n[2]);
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
  fs::remove_all(run);
}

}  // namespace
}  // namespace swarmsim::testing
