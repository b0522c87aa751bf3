// Range-and-bearing links in the viewer page (headless Chromium): a
// recording of tests/data/viewer/rab_links (a and b hear each other, b
// hears c one way, d hears no one) draws one line a-b (both ways) and one
// b-c (one way), between the boards' recorded positions, in the page's
// picture; the "links" box hides them and shows them again.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "tests/swarm/run_program.h"
#include "tests/swarm/viewer/browser.h"

namespace swarmsim::testing {
namespace {
namespace fs = std::filesystem;

class RabLinksBrowserTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string missing = BrowserMissing(); !missing.empty()) GTEST_SKIP() << missing;
    run_ = FreshTempDir("viewer_browser", "rab_links");
    const CommandResult run = RunProgram(
        "run " + std::string(SWARMSIM_SOURCE_DIR) +
        "/tests/data/viewer/rab_links/world.yaml --quiet --record --out " + run_.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  void TearDown() override {
    if (!run_.empty()) fs::remove_all(run_);
  }
  fs::path run_;
};

// Is there a link-coloured (cyan: blue and green well above red) pixel
// within 2 pixels of (x, y)?
bool CyanNear(const Image& image, double x, double y) {
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const int px = static_cast<int>(std::lround(x)) + dx,
                py = static_cast<int>(std::lround(y)) + dy;
      if (px < 0 || py < 0 || px >= image.width || py >= image.height) continue;
      const uint8_t* c = image.At(px, py);
      if (c[2] > 100 && c[1] > 100 && c[0] + 30 < c[1]) return true;
    }
  return false;
}

TEST_F(RabLinksBrowserTest, LinesJoinTheRobotsThatHeardEachOtherAndTheBoxHidesThem) {
  ViewServer server(run_.string(), (run_ / "server.log").string());
  ASSERT_FALSE(server.Address().empty()) << server.Output();
  Browser browser;
  browser.Open(server.Address());
  ASSERT_EQ(browser.WaitForViewer(), "");
  browser.Run("swarmsimViewer.topDown(); swarmsimViewer.setRecord(3);");
  EXPECT_EQ(
      browser.Run("const v = swarmsimViewer.view;"
                  "return {lines: v.linkCount, mutual: v.mutualLinks, shown: v.links.visible};"),
      json::parse(R"({"lines": 2, "mutual": 1, "shown": true})"));
  // The a-b line runs from a's board to b's: 0.1 m up, 1 m apart on x.
  const json ends = browser.Run(
      "const p = swarmsimViewer.view.links.geometry.attributes.position.array;"
      "return [...p.slice(0, 6)];");
  const double a[3] = {ends[0], ends[1], ends[2]}, b[3] = {ends[3], ends[4], ends[5]};
  EXPECT_NEAR(std::hypot(b[0] - a[0], b[1] - a[1]), 1.0, 1e-3);
  EXPECT_NEAR(a[2], 0.1, 1e-3);
  EXPECT_NEAR(b[2], 0.1, 1e-3);
  // In the picture: a cyan line at a quarter and three quarters along a-b
  // (not on the pucks), none with the box unticked, back when ticked.
  const auto probe = [&] {
    const json q1 = browser.Run("return swarmsimViewer.project(0.25, 0, 0.1);");
    const json q3 = browser.Run("return swarmsimViewer.project(0.75, 0, 0.1);");
    const Image image = browser.Screenshot();
    return CyanNear(image, q1["x"].get<double>(), q1["y"].get<double>()) &&
           CyanNear(image, q3["x"].get<double>(), q3["y"].get<double>());
  };
  EXPECT_TRUE(probe());
  browser.Run("document.getElementById('show-links').click(); swarmsimViewer.view.render();");
  EXPECT_EQ(browser.Run("return swarmsimViewer.view.links.visible;"), false);
  EXPECT_FALSE(probe());
  browser.Run("document.getElementById('show-links').click(); swarmsimViewer.view.render();");
  EXPECT_TRUE(probe());
  // Before the first sense phase (record 0) nothing was heard.
  browser.Run("swarmsimViewer.setRecord(0);");
  EXPECT_EQ(browser.Run("return swarmsimViewer.view.linkCount;"), 0);
  EXPECT_EQ(browser.ConsoleErrors(), std::vector<std::string>{});
}

}  // namespace
}  // namespace swarmsim::testing
